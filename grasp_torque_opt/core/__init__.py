"""
The numerical core: no ROS, no solver (numpy, SciPy's linear algebra and Pinocchio only).

Scenario files, the hand model, contact frames, the grasp matrix G and hand
Jacobian J, the friction polygons, the tau-QP's data (a plain dataclass), the
certificate, the :class:`~grasp_torque_opt.core.solution.Solution` type and its
JSON form. A test imports it with ROS and every solver blocked.
"""
