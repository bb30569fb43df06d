"""Evaluation of the paper's two use cases against the simulator's ground truth (no ROS).

Semantic maps (§5.4, Table 3): :mod:`.semantic_map` (the box format), :mod:`.fusion` (per-capture
detections -> a map), :mod:`.mappers` (oracle and degraded reference mappers), :mod:`.semantic_eval`
(precision/recall per house and type, the plan picture).

Appearance-based localization (§5.5, Table 4): :mod:`.descriptors` (image -> vector),
:mod:`.localization` (matching fused with odometry), :mod:`.recording` (grid maps and routes as
datasets), :mod:`.table4` (the protocol, the error matrix and its heat map).
"""
