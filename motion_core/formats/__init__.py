"""File formats: BVH, glTF, retargeting of other skeletons, and the export of a Motion."""
