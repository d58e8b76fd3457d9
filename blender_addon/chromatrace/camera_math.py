"""The scene format's pinhole camera in Blender's terms (pure Python, no bpy).

Blender's camera looks down its local -Z with +Y up the image and +X to the right. The scene format gives
position, look_at and up (docs/scene-format.md, "Camera"): forward = look_at - position, right = forward × up,
image_up = right × forward. The focal length comes from `chromatrace check-scene` (core's Camera, the one
definition of the field-of-view rules).
"""

import math


def _sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _unit(a):
    n = math.sqrt(sum(c * c for c in a))
    return [c / n for c in a]


def camera_basis(position, look_at, up):
    """3×3 rotation (rows) whose columns are Blender's camera axes X = right, Y = image up, Z = -forward."""
    forward = _unit(_sub(look_at, position))
    right = _unit(_cross(forward, up))
    image_up = _cross(right, forward)
    back = [-c for c in forward]
    return [[right[i], image_up[i], back[i]] for i in range(3)]
