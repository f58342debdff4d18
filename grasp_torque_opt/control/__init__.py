"""
The control cycle on plain arrays (input checks, staleness, the gate, the fault
policy) and its diagnostics: everything the node does, without ROS.
"""
