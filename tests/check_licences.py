# SPDX-License-Identifier: Apache-2.0
"""The project's licences, as the repository states them: Apache-2.0 for everything but the Blender add-on, which is
GPL-3.0-or-later (its manifest says so, and Blender's extension platform requires it). Checks that both licence
texts are present, that the add-on's manifest declares its own, and that every source file — C++, JavaScript,
Python, shell, CMake, any script — names its licence in an SPDX line among its first three.

    python3 tests/check_licences.py SOURCE_DIR
"""

import os
import re
import sys

SOURCE = re.compile(r"(\.(cpp|h|js|mjs|py|sh|cmake)|^CMakeLists\.txt|^run)$")
SKIP = {".git", "build", "node_modules", "seeds"}


def expected(relative):
    return "GPL-3.0-or-later" if relative.startswith("blender_addon" + os.sep) else "Apache-2.0"


def main(root):
    problems = []
    texts = {"LICENSE": "Apache License\n                           Version 2.0, January 2004",
             os.path.join("blender_addon", "LICENSE"): "GNU GENERAL PUBLIC LICENSE\n                       Version 3, 29 June 2007"}
    for name, start in texts.items():
        path = os.path.join(root, name)
        if not os.path.isfile(path) or start not in open(path, encoding="utf-8").read(400):
            problems.append(f"{name}: not the licence's text ({start.split()[0]} …)")
    manifest = open(os.path.join(root, "blender_addon", "chromatrace", "blender_manifest.toml"), encoding="utf-8").read()
    if not re.search(r'^license = \["SPDX:GPL-3.0-or-later"\]$', manifest, re.M):
        problems.append("blender_addon/chromatrace/blender_manifest.toml: license is not [\"SPDX:GPL-3.0-or-later\"]")
    checked = 0
    for folder, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if d not in SKIP and not d.startswith("build")]
        for f in files:
            path = os.path.join(folder, f)
            if not SOURCE.search(f) and not (os.access(path, os.X_OK) and open(path, "rb").read(2) == b"#!"):
                continue
            relative = os.path.relpath(path, root)
            with open(path, encoding="utf-8") as fh:
                head = [fh.readline() for _ in range(3)]
            found = [m.group(1) for line in head for m in [re.search(r"SPDX-License-Identifier: (\S+)", line)] if m]
            checked += 1
            if found != [expected(relative)]:
                problems.append(f"{relative}: SPDX-License-Identifier {found[0] if found else 'missing'}, "
                                f"expected {expected(relative)}")
    for p in problems:
        print(p, file=sys.stderr)
    print(f"{checked} source files checked, {len(problems)} problems")
    return 1 if problems or checked < 300 else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")))
