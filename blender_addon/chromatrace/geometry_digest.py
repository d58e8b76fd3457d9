# SPDX-License-Identifier: GPL-3.0-or-later
"""Digests that tell whether an imported object or camera is still as imported (then export writes the
analytic shape or camera of the scene file, exactly, instead of what Blender's float32 data says)."""

import hashlib
from array import array


def update_with_mesh(digest, mesh):
    """Feeds a mesh's vertex positions and face corners (its triangles) into a hashlib digest."""
    co = array("f", [0.0]) * (len(mesh.vertices) * 3)
    mesh.vertices.foreach_get("co", co)
    loops = array("i", [0]) * len(mesh.loops)
    mesh.loops.foreach_get("vertex_index", loops)
    digest.update(co.tobytes())
    digest.update(loops.tobytes())


def object_digest(ob):
    digest = hashlib.sha256()
    digest.update(repr([list(row) for row in ob.matrix_world]).encode())
    update_with_mesh(digest, ob.data)
    digest.update(repr([(m.name, m.type) for m in ob.modifiers]).encode())  # a modifier changes the mesh
    return digest.hexdigest()


def camera_digest(ob):
    data = ob.data
    text = repr(([list(row) for row in ob.matrix_world], data.lens, data.sensor_width, data.sensor_height,
                 data.sensor_fit, data.shift_x, data.shift_y, data.type))
    return hashlib.sha256(text.encode()).hexdigest()
