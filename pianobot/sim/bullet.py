"""PyBullet, imported once without the banner its C module prints on standard output."""

from __future__ import annotations

import os
import sys


def _import_quietly():
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            import pybullet
    finally:
        os.dup2(saved, 1)
        os.close(saved)
    return pybullet


p = _import_quietly()
