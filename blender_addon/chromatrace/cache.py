"""Where finished band-group renders wait for a resumed run (pure Python, no bpy).

A run's renders go to <root>/<key>/, the key a hash of everything that decides their pixels (scene content,
band values, settings, Blender version). A run that is killed leaves the finished renders there; the next
run with the same scene and settings finds them and renders only the rest. Each render is written under a
temporary name and renamed, so a file in the cache is always complete.
"""

import hashlib
import json
import os
import shutil


def default_root():
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "chromatrace", "blender")


def cache_key(description):
    """A hex digest of a JSON-serialisable description (dict keys sorted, floats as repr)."""
    text = json.dumps(description, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:24]


def cache_directory(root, key):
    path = os.path.join(root or default_root(), key)
    os.makedirs(path, exist_ok=True)
    return path


def commit(temporary, final):
    """Moves a finished render into place (atomic on one file system)."""
    os.replace(temporary, final)


def remove(directory):
    shutil.rmtree(directory, ignore_errors=True)
