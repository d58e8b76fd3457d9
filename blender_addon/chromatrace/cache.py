# SPDX-License-Identifier: GPL-3.0-or-later
"""Where finished band-group renders wait for a resumed run (pure Python, no bpy).

A run's renders go to <root>/<key>/, the key a hash of everything that decides their pixels (scene content,
band values, settings, Blender version). A run that is killed leaves the finished renders there; the next
run with the same scene and settings finds them and renders only the rest. Each render is written under a
temporary name, read back, and renamed only when it reads whole, so a file in the cache is complete: Cycles
reports success even when its write failed (a full disk leaves a file cut short). A file already in the cache
that does not read back is rendered again.
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


def commit(temporary, final, problem):
    """Moves a finished render into place (atomic on one file system) when `problem` (a function of a file that
    says why it cannot be used, or None) finds none; otherwise removes it and raises RuntimeError."""
    reason = problem(temporary)
    if reason is not None:
        discard(temporary)
        raise RuntimeError(f"Cycles did not write {os.path.basename(final)} completely (a full disk?): {reason}")
    os.replace(temporary, final)


def discard(path):
    try:
        os.remove(path)
    except FileNotFoundError:
        pass


def write_json(path, document):
    """Writes a JSON file under a temporary name and renames it: a failed write (a full disk) leaves no cut file."""
    temporary = f"{path}.{os.getpid()}.partial"
    try:
        with open(temporary, "w") as f:
            json.dump(document, f, indent=1)
        os.replace(temporary, path)
    except BaseException:
        discard(temporary)
        raise


def remove(directory):
    shutil.rmtree(directory, ignore_errors=True)
