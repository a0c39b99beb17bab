"""Experiment: excerpts of Bach chorales (none of the corpus test or validation pieces) as MIDI files."""
import sys, warnings, pickle
warnings.simplefilter("ignore")
from pathlib import Path
from music21 import corpus
from benchmarks.corpus import write_excerpt, EXCERPTS, VALIDATION
from pianobot.perform.hands import two_hands
from pianobot.music.load import LoadOptions
from pianobot.music.instrument import THUMB
used = {p for _, p, *_ in EXCERPTS + VALIDATION}
out = Path("out/s23/chorales"); out.mkdir(parents=True, exist_ok=True)
paths = sorted({str(p).split("corpus/")[-1].rsplit(".", 1)[0] for p in corpus.getComposer("bach") if str(p).endswith(".mxl")})
paths = [p for p in paths if p not in used and p != "bach/bwv846"]
n = int(sys.argv[1])
pieces = []
for p in paths[:n]:
    f = out / (p.split("/")[-1].replace(".", "-") + ".mid")
    try:
        write_excerpt(p, None, 0, f)
        r = two_hands(f, LoadOptions(), THUMB)
    except Exception as e:
        print(p, "skipped:", str(e)[:80]); continue
    if r is not None:
        pieces.append(r.piece)
pickle.dump(pieces, open("out/s23/chorales.pkl", "wb"))
print(len(pieces), "pieces of", len(paths[:n]), "of", len(paths))
