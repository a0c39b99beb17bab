"""Whether two checkouts play the same, note for note: a digest of every played note (onset, pitch,
offset, velocity, finger, hand) of the examples, with the scripted pianist and with the packaged
general policies, one and two hands.

    python -m benchmarks.unchanged                       # this checkout's digests
    python -m benchmarks.unchanged --peer /path/to/other # both, and whether they agree

A refactoring that promises to change nothing (a new hand abstraction, one reading pipeline)
shows it here: each checkout plays in a process of its own (``PYTHONPATH`` set to it), from an
empty folder (no model store: the packaged policies play), hand start 0.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).parent.parent
EXAMPLES = ROOT / "examples" / "midi"
PLAYS = [
    ("mary", "scripted"),
    ("mary", "sac"),
    ("twinkle", "scripted"),
    ("c-major-scale", "scripted"),
    ("c-major-scale", "sac"),
    ("chorale-performed", "scripted"),
    ("chorale-performed", "sac"),
    ("prelude-performed", "scripted"),
    ("prelude-performed", "sac"),
    ("nocturne-performed", "scripted"),
    ("nocturne-performed", "sac"),
]
PLAYER = """
import hashlib, json, sys, warnings
warnings.simplefilter("ignore")
import torch
torch.set_num_threads(1)
import pianobot
out = {}
for name, controller in json.loads(sys.argv[1]):
    path = sys.argv[2] + "/" + name + ".mid"
    piece = pianobot.load_two_hands(path) if "performed" in name else pianobot.load_piece(path)
    performance = pianobot.play(piece, controller=controller)
    notes = [(n.onset, n.pitch, n.offset, n.velocity, n.finger, n.hand) for n in performance.played.notes]
    digest = hashlib.sha256(json.dumps(notes).encode()).hexdigest()[:12]
    out[name + " " + controller] = [digest, round(performance.report().f1, 4)]
print(json.dumps(out))
"""


def digests(checkout: Path) -> dict[str, list]:
    """{'<example> <controller>': [digest of the played notes, note F1]} as ``checkout`` plays them."""
    env = dict(os.environ, PYTHONPATH=str(checkout))
    with tempfile.TemporaryDirectory() as empty:
        result = subprocess.run(
            [sys.executable, "-c", PLAYER, json.dumps(PLAYS), str(EXAMPLES)],
            cwd=empty,
            env=env,
            check=True,
            capture_output=True,
            text=True,
        )
    return json.loads(result.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--peer", type=Path, default=None, help="another checkout to compare with")
    args = parser.parse_args(argv)
    ours = digests(ROOT)
    theirs = digests(args.peer) if args.peer else {}
    for key, (digest, f1) in ours.items():
        other = theirs.get(key)
        beside = (
            "" if other is None else ("  same" if other == [digest, f1] else f"  DIFFERS: {other[0]} F1 {other[1]}")
        )
        print(f"{key:32} {digest}  F1 {f1:.4f}{beside}")
    return 1 if theirs and theirs != ours else 0


if __name__ == "__main__":
    sys.exit(main())
