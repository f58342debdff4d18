"""Minimum-effort grasp joint torques with linearized soft-finger friction cones.

The numerical core (everything but :mod:`grasp_torque_opt.node`) never imports
rclpy or message types.
"""
