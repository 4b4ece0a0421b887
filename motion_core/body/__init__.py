"""The body: the HumanML3D skeleton, its 263-d features, inverse kinematics and foot geometry.

The lowest layer with ``nn``: it imports nothing else of motion_core.
"""
