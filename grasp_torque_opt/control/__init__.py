"""
The control cycle on plain arrays and its diagnostics: everything the node does, without ROS.

The cycle covers the input checks, staleness, the gate and the fault policy.
"""
