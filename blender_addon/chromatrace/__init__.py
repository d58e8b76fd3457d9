# SPDX-License-Identifier: GPL-3.0-or-later
"""chromatrace for Blender: spectral rendering with Cycles by band multiplexing.

Each render carries three bands of the spectrum in R, G and B: every spectral colour input (reflectances,
light and emission colours) gets its band averages, Cycles renders, and the channels are filed under their
wavelengths in a spectral OpenEXR (the layout of docs/spectral-exr.md) by `chromatrace assemble`. Spectra,
band averages, tessellation and the EXR writer are chromatrace's C++ core, run as the `chromatrace`
command; this package is properties (properties.py), panels (ui.py), operators (operators.py) and the
render driver (spectral_render.py) over its steps: where each colour comes from (node_resolution.py), image
textures (textures.py), the cache key's description (cache_description.py), the scene set up for Cycles
(render_setup.py) and the pre-flight check (preflight.py). The pure-Python parts (bands, components, manifest,
cache, journal, node rules, PLY, batch arguments, the scene's parts) are free of bpy so plain Python tests them.
"""

bl_info = {
    "name": "chromatrace",
    "author": "chromatrace",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render / Material / Light; File > Import/Export > chromatrace scene",
    "description": "Spectral rendering with Cycles by band multiplexing; chromatrace scene import and export",
    "category": "Render",
}

VERSION = bl_info["version"]

try:
    import bpy  # noqa: F401
except ImportError:  # imported by plain Python for the tests of the pure modules
    bpy = None

if bpy is not None:
    from . import operators, properties, ui

    _modules = (properties, operators, ui)

    def register():
        for module in _modules:
            module.register()

    def unregister():
        for module in reversed(_modules):
            module.unregister()

