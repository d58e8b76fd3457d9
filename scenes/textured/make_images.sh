#!/bin/sh
# SPDX-License-Identifier: Apache-2.0
# Makes the textured scene's images with OpenImageIO's oiiotool (./setup.sh installs it):
#   floor.png  16×16 8-bit sRGB: 4×4 blocks of eight saturated and pale colours (a checker of colours)
#   panel.png  16×16 8-bit sRGB: a left-to-right ramp from orange to teal over a top-to-bottom darkening
#   sky.exr    64×32 float, linear, equirectangular (top row the zenith): a sky brighter at the zenith than at
#              the horizon, a darker brown ground below the horizon, and a warm sun 20 × the sky, 4 × 2 texels
set -e
cd "$(dirname "$0")/textures"
oiiotool --create 16x16 3 \
  --fill:color=0.85,0.15,0.10 4x4+0+0 --fill:color=0.95,0.85,0.20 4x4+4+0 --fill:color=0.15,0.55,0.20 4x4+8+0 --fill:color=0.20,0.30,0.80 4x4+12+0 \
  --fill:color=0.90,0.90,0.85 4x4+0+4 --fill:color=0.60,0.20,0.60 4x4+4+4 --fill:color=0.10,0.70,0.75 4x4+8+4 --fill:color=0.50,0.35,0.20 4x4+12+4 \
  --fill:color=0.15,0.55,0.20 4x4+0+8 --fill:color=0.20,0.30,0.80 4x4+4+8 --fill:color=0.85,0.15,0.10 4x4+8+8 --fill:color=0.95,0.85,0.20 4x4+12+8 \
  --fill:color=0.10,0.70,0.75 4x4+0+12 --fill:color=0.50,0.35,0.20 4x4+4+12 --fill:color=0.90,0.90,0.85 4x4+8+12 --fill:color=0.60,0.20,0.60 4x4+12+12 \
  -d uint8 -o floor.png
oiiotool --create 16x16 3 --fill:left=0.95,0.55,0.15:right=0.10,0.65,0.60 16x16 \
  --create 16x16 3 --fill:top=1,1,1:bottom=0.45,0.45,0.45 16x16 --mul -d uint8 -o panel.png
oiiotool --create 64x32 3 --fill:top=0.35,0.55,1.00:bottom=0.75,0.85,1.00 64x16+0+0 \
  --fill:top=0.22,0.16,0.10:bottom=0.12,0.09,0.06 64x16+0+16 \
  --fill:color=16,14,11 4x2+40+6 -d float -o sky.exr
