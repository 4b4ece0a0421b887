"""Motion Mamba Studio core: skeleton, features, data sets, text encoder, models, exports.

This package never imports Gradio; the app asks it, never the other way round.
"""

from .features import Normalizer, features_to_joints, joints_to_features
from .skeleton import HUMANML3D, KIT, get_skeleton

__all__ = [
    "HUMANML3D",
    "KIT",
    "Normalizer",
    "features_to_joints",
    "get_skeleton",
    "joints_to_features",
]
__version__ = "0.1.0"
