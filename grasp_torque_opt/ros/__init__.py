"""
The ROS 2 adapter: ``grasp_torque_node`` and the demo hand driver.

They are the only modules that import rclpy and message types.
"""
