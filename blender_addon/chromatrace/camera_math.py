# SPDX-License-Identifier: GPL-3.0-or-later
"""The scene format's pinhole camera in Blender's terms, and Blender's camera in the header's (pure Python, no
bpy).

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


def camera_description(scene, resolution):
    """Blender's camera as `chromatrace render` describes its camera in the header (chromatrace.camera)."""
    camera = scene.camera
    width, height = resolution
    data = camera.data
    m = camera.matrix_world
    position = [m[i][3] for i in range(3)]
    forward = [-m[i][2] for i in range(3)]
    up = [m[i][1] for i in range(3)]
    fit = data.sensor_fit
    if fit == "VERTICAL" or (fit == "AUTO" and height > width):
        sensor = (data.sensor_height if fit == "VERTICAL" else data.sensor_width) * width / height
    else:
        sensor = data.sensor_width
    tan_w = 0.5 * sensor / data.lens
    tan_h = tan_w * height / width
    return {"position": position, "look_at": [position[i] + forward[i] for i in range(3)], "up": up,
            "horizontal_fov_deg": math.degrees(2 * math.atan(tan_w)), "vertical_fov_deg": math.degrees(2 * math.atan(tan_h)),
            "sensor_width_mm": sensor, "focal_length_mm": data.lens, "resolution": [width, height]}
