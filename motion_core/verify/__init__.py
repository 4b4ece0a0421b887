"""The automatic verifier: per-action rules (``rules``) and realism bounds (``realism``) on joint motions.

Used by the corpus, evaluation, mocap import and training curves; it needs only ``body``.
``kind_rules`` holds the rules of the kinds registered in ``motion_core.corpus.kinds``;
importing the package puts them into ``rules.verify``.
"""

from . import chain as _chain  # noqa: F401  (several actions in one motion, in order)
from . import kind_rules  # noqa: F401  (registers its rules with rules.verify)
from . import stairs_rules as _stairs_rules  # noqa: F401  (the stairs kinds' rules)
