"""Network building blocks shared by the models: selective scans, the diffusion schedule, the text encoder.

The lowest layer with ``body``: it imports nothing else of motion_core.
"""
