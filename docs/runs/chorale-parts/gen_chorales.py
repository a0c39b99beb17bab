"""Experiment: excerpts of Bach chorales (none of the corpus test or validation pieces) as MIDI
files, each read as `pianobot play` reads it with the thumb, pickled to out/s23/chorales.pkl.

    PYTHONPATH=. python docs/runs/chorale-parts/gen_chorales.py 160
"""

import pickle
import sys
import warnings
from pathlib import Path

from music21 import corpus

from benchmarks.corpus import EXCERPTS, VALIDATION, write_excerpt
from pianobot.music.instrument import THUMB
from pianobot.music.load import LoadOptions
from pianobot.perform.together import two_hands

warnings.simplefilter("ignore")
used = {path for _, path, *_ in EXCERPTS + VALIDATION} | {"bach/bwv846"}
out = Path("out/s23/chorales")
out.mkdir(parents=True, exist_ok=True)
found = sorted(
    {str(p).split("corpus/")[-1].rsplit(".", 1)[0] for p in corpus.getComposer("bach") if str(p).endswith(".mxl")}
)
paths = [p for p in found if p not in used][: int(sys.argv[1])]
pieces = []
for path in paths:
    file = out / (path.split("/")[-1].replace(".", "-") + ".mid")
    try:
        write_excerpt(path, None, 0, file)
        reading = two_hands(file, LoadOptions(), THUMB)
    except Exception as error:  # (an experiment: a chorale music21 cannot excerpt is left out)
        print(path, "skipped:", str(error)[:80])
        continue
    if reading is not None:
        pieces.append(reading.piece)
with open("out/s23/chorales.pkl", "wb") as f:
    pickle.dump(pieces, f)
print(len(pieces), "pieces of", len(paths))
