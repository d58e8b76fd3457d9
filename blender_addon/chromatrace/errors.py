# SPDX-License-Identifier: GPL-3.0-or-later
"""Errors the add-on reports to the user (pure Python).

BadInput is something the user can fix (a scene field, an option, a node tree): batch.py exits with 2 and
prints its one-line message; anything else is a runtime failure (exit 1).
"""


class BadInput(Exception):
    pass

