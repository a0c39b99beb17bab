"""The HTML report (`play --html`, `score --html`): one page that opens offline, and that a real
headless browser renders, roll and video (issue 36, item 1)."""

import base64
import json
import re
import shutil
import subprocess
from dataclasses import replace
from pathlib import Path

import pytest
from conftest import assert_one_line_error, run

from pianobot.music.midi_io import write_midi
from pianobot.music.piece import Piece

EXAMPLES = Path(__file__).parent.parent / "examples" / "midi"
CHROMIUM = next(
    (shutil.which(name) for name in ("chromium", "chromium-browser", "google-chrome") if shutil.which(name)), None
)
NO_BROWSER = "no headless Chromium here: `make browser` installs Debian's chromium (as root), as .ci/run does"


@pytest.fixture(scope="module")
def played(tmp_path_factory):
    """The scripted pianist plays three-note.mid with a video, a WAV and the HTML report."""
    folder = tmp_path_factory.mktemp("report")
    result = run(
        "play",
        EXAMPLES / "three-note.mid",
        "-o",
        folder / "out.mid",
        "--controller",
        "scripted",
        "--video",
        folder / "out.mp4",
        "--wav",
        folder / "out.wav",
        "--html",
        folder / "out.html",
    )
    assert result.exit_code == 0, result.output
    assert f"report to open in a browser written to {folder / 'out.html'}" in result.output
    return folder


def test_the_play_report_is_one_self_contained_page(played):
    page = (played / "out.html").read_text()
    report = json.loads((played / "out.report.json").read_text())
    links = re.findall(r"""(?:src|href)\s*=\s*['"]([^'"]*)""", page)
    assert links and all(link.startswith(("data:", "#")) for link in links), links  # nothing fetched from elsewhere
    video = re.search(r"<video[^>]*src='data:video/mp4;base64,([^']+)'", page).group(1)
    audio = re.search(r"<audio[^>]*src='data:audio/wav;base64,([^']+)'", page).group(1)
    assert base64.b64decode(video) == (played / "out.mp4").read_bytes()
    assert base64.b64decode(audio) == (played / "out.wav").read_bytes()
    roll = page[page.index("<section id='roll'>") : page.index("<section id='errors'>")]
    assert roll.count('id="played-') == report["played_notes"] and roll.count('id="score-') == report["reference_notes"]
    phrases = page[page.index("<section id='phrases'>") : page.index("<section id='notes'>")]
    assert "scripted pianist" in phrases and "0.00-" in phrases
    notes = page[page.index("<section id='notes'>") :]
    assert notes.count("<tr class='matched'>") == report["matched_notes"] == 3
    for figure in ("note F1", "velocity error", "timing error", "key-press F1 per step (RoboPianist)"):
        assert f"<td>{figure}</td>" in page  # the first few on show, the rest under "every figure"


def test_score_writes_the_report_with_missed_notes_marked(tmp_path, scale):
    reference = write_midi(scale, tmp_path / "ref.mid")
    notes = list(scale.notes)
    notes[1] = replace(notes[1], velocity=notes[1].velocity - 20)
    performance = write_midi(Piece(tuple(notes[:3]), bpm=60), tmp_path / "played.mid")
    result = run("score", performance, reference, "--html", tmp_path / "r.html", "--no-notes")
    assert result.exit_code == 0, result.output
    page = (tmp_path / "r.html").read_text()
    assert page.count("<tr class='missed'>") == 1 and page.count("<tr class='matched'>") == 3
    assert "<td>-20</td>" in page and "<video" not in page and "id='phrases'" not in page
    assert_one_line_error(run("score", performance, reference, "--html", tmp_path / "r.htm.txt"), "*.html")
    assert_one_line_error(
        run("play", EXAMPLES / "one-note.mid", "-o", tmp_path / "x.mid", "--html", tmp_path / "r.pdf"), "*.html"
    )
    assert not (tmp_path / "x.mid").exists()


CHECK = """<script>
window.addEventListener('load', async () => {
  const out = {};
  out.played = document.querySelectorAll('#roll svg g[id^="played-"]').length;
  out.score = document.querySelectorAll('#roll svg g[id^="score-"]').length;
  const box = document.querySelector('#roll svg').getBoundingClientRect();
  out.roll = [box.width, box.height];
  const video = document.querySelector('video');
  video.muted = true;
  try { await video.play(); } catch (e) { out.refused = String(e); }
  await new Promise(done => setTimeout(done, 1000));
  out.time = video.currentTime; out.size = [video.videoWidth, video.videoHeight]; out.duration = video.duration;
  const pre = document.createElement('pre'); pre.id = 'check'; pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});
</script>"""


@pytest.mark.skipif(CHROMIUM is None, reason=NO_BROWSER)
def test_a_headless_browser_renders_the_roll_and_plays_the_video(played):
    """Chromium opens the page (a copy with a script that looks, added before </body>): the roll
    has a box for every note, and the video decodes and plays."""
    report = json.loads((played / "out.report.json").read_text())
    page = (played / "out.html").read_text().replace("</body>", CHECK + "</body>")
    (played / "check.html").write_text(page)
    dom = subprocess.run(
        [
            CHROMIUM,
            "--headless",
            "--no-sandbox",  # (as root, in CI)
            "--disable-gpu",
            "--disable-dev-shm-usage",
            "--autoplay-policy=no-user-gesture-required",
            "--virtual-time-budget=5000",
            "--dump-dom",
            (played / "check.html").as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    ).stdout
    found = re.search(r'<pre id="check">(.*?)</pre>', dom)
    assert found, dom[-2000:]
    seen = json.loads(found.group(1))
    assert seen["played"] == report["played_notes"] and seen["score"] == report["reference_notes"], seen
    assert seen["roll"][0] > 300 and seen["roll"][1] > 100, seen  # drawn, at a size one can read
    assert "refused" not in seen and seen["time"] > 0, seen  # it plays
    assert seen["size"][0] > 0 and seen["duration"] > 3, seen  # frames decoded; three notes of a second each


@pytest.mark.parametrize("model", ["allegro", "pianist"])
def test_a_one_hand_report_names_the_hand_that_played(model):
    """The page says which hand played, as the report's JSON does (hand_model, fingers): a
    performance of the pianist's hand is not taken for the Allegro-like hand's."""
    import pianobot
    from pianobot.perform.report import html_report
    from pianobot.sim.hand import default_fingers

    spec = default_fingers(model)
    piece = pianobot.load_piece(EXAMPLES / "one-note.mid")
    performance = pianobot.play(piece, controller="scripted", hand=spec)
    assert performance.to_dict()["hand_model"] == model
    page = html_report(performance.report(), "one-note", plan=performance.plan, seed=0)
    head = page[: page.index("<section id='figures'>")]
    assert f"with fingers {spec.describe()}" in head
    assert ("pianist hand" in head) == (model == "pianist")
