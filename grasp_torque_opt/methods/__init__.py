"""
Every method behind one entry point, and their comparison (the paper's Table 2).

:func:`solve` runs the kinematics, builds the problem, solves it with a backend
or a reference method, certifies the answer and decides the status.
"""

from grasp_torque_opt.methods.dispatch import METHODS, solve

__all__ = ['METHODS', 'solve']
