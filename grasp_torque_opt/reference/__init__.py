"""
Reference methods and independent checks, beside the product's tau-QP.

The contact-force QP, the exact cone as an SOCP and as an NLP (Clarabel, SciPy
SLSQP), and the HiGHS LP that confirms an infeasible verdict. They build on the
core only; :func:`grasp_torque_opt.methods.solve` dispatches to them.
"""
