"""The automatic verifier: per-action rules (``rules``) and realism bounds (``realism``) on joint motions.

Used by the corpus, evaluation, mocap import and training curves; it needs only ``body``.
"""
