"""Inference: the methods behind one interface.

``base`` (Motion, limits, the Method protocol), ``checkpoints`` (every checkpoint read and
write), one module per method family (``latent_diffusion``, ``masked``), ``registry`` (the
table of methods) and ``generation`` (the public ``generate`` / ``generate_batch``).
"""
