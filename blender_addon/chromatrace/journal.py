# SPDX-License-Identifier: GPL-3.0-or-later
"""Undo journal: every change the spectral render makes to Blender data is made through it, so that it
can put back exactly what was there (pure Python; it works on any object with attributes).

    journal = Journal()
    try:
        journal.set(scene.cycles, "samples", 16)
        journal.set(socket, "default_value", (0.2, 0.5, 0.1, 1.0))
        journal.call_on_restore(lambda: view_layer.lightgroups.remove(group))
        ...
    finally:
        journal.restore()

The first value seen for each (object, attribute) is kept; restore() puts values back newest first and
runs the registered undo actions in the same reverse order, then forgets them (so calling it twice is
harmless). Failures during restore do not stop it: all are attempted, then the first is re-raised.
"""


def _identity(target):
    # bpy wraps the same datablock in a new Python object on every access, so id() is not stable;
    # as_pointer() is (the address of the underlying C struct).
    pointer = getattr(target, "as_pointer", None)
    return ("ptr", pointer()) if callable(pointer) else ("id", id(target))


def _copy(value):
    # bpy arrays (colours, vectors) are views into Blender's memory: keep a copy.
    if isinstance(value, (str, bytes, int, float, bool)) or value is None:
        return value
    try:
        return tuple(value)
    except TypeError:
        return value


class Journal:
    def __init__(self):
        self._seen = set()
        self._undo = []  # callables, oldest first
        self._keep_alive = []

    def __len__(self):
        return len(self._undo)

    def set(self, target, attribute, value):
        """setattr(target, attribute, value), remembering the value it replaces (the first time)."""
        key = (_identity(target), attribute)
        if key not in self._seen:
            self._seen.add(key)
            old = _copy(getattr(target, attribute))
            self._keep_alive.append(target)
            self._undo.append(lambda: setattr(target, attribute, old))
        setattr(target, attribute, value)

    def set_together(self, target, values):
        """Sets several attributes whose valid values depend on each other (an image format and its bit
        depth): they are set in the given order and, on restore, put back in that same order."""
        old = [(attribute, _copy(getattr(target, attribute))) for attribute, _value in values]
        self._keep_alive.append(target)
        self._undo.append(lambda: [setattr(target, attribute, value) for attribute, value in old])
        for attribute, value in values:
            setattr(target, attribute, value)

    def call_on_restore(self, action):
        """Registers an undo action (e.g. removing something the render created)."""
        self._undo.append(action)

    def restore(self):
        errors = []
        while self._undo:
            action = self._undo.pop()
            try:
                action()
            except Exception as e:  # keep restoring the rest; report afterwards
                errors.append(e)
        self._seen.clear()
        self._keep_alive.clear()
        if errors:
            raise errors[0]
