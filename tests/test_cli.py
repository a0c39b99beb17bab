import json
import re
from dataclasses import replace
from pathlib import Path

import mido
import numpy as np
import pytest
from conftest import assert_one_line_error, run
from typer.testing import CliRunner

from pianobot.agent.general import PACKAGED
from pianobot.music.midi_io import write_midi
from pianobot.music.piece import Note, Piece
from pianobot.music.pig import sidecar_for, write_pig

runner = CliRunner()
EXAMPLES = Path(__file__).parent.parent / "examples" / "midi"


def test_score_of_a_file_against_itself(scale_file):
    result = run("score", scale_file, scale_file)
    assert result.exit_code == 0, result.output
    assert "note F1" in result.output and "1.000" in result.output


def test_score_json_holds_the_expected_figures(tmp_path, scale):
    notes = list(scale.notes)
    notes[1] = replace(notes[1], velocity=notes[1].velocity - 10)
    notes[2] = replace(notes[2], onset=notes[2].onset + 0.03)
    del notes[3]
    reference = write_midi(scale, tmp_path / "ref.mid")
    played = write_midi(Piece(tuple(notes), bpm=60), tmp_path / "played.mid")
    result = run("score", played, reference, "--json", tmp_path / "r.json", "--plot", tmp_path / "r.png")
    assert result.exit_code == 0, result.output
    figures = json.loads((tmp_path / "r.json").read_text())
    assert figures["f1"] == pytest.approx(6 / 7)
    assert figures["velocity_mae"] == pytest.approx(10 / 3)
    assert figures["velocity_max_error"] == 10
    assert figures["onset_error_max"] == pytest.approx(0.03)
    assert [n["status"] for n in figures["notes"]] == ["matched", "matched", "matched", "missed"]
    assert (tmp_path / "r.png").read_bytes()[:4] == b"\x89PNG"


def test_onset_tolerance_option_changes_matching(tmp_path, scale):
    late = scale.shift(0.04)
    reference, played = write_midi(scale, tmp_path / "ref.mid"), write_midi(late, tmp_path / "late.mid")
    run("score", played, reference, "--json", tmp_path / "a.json")
    run("score", played, reference, "--json", tmp_path / "b.json", "--onset-tolerance", "0.03")
    assert json.loads((tmp_path / "a.json").read_text())["f1"] == 1.0
    assert json.loads((tmp_path / "b.json").read_text())["f1"] == 0.0


def test_inspect_shows_notes_phrases_and_range():
    result = run("inspect", EXAMPLES / "twinkle.mid")
    assert result.exit_code == 0, result.output
    assert "14 notes" in result.output and "3 phrases" in result.output
    assert "playable on C4-B5" in result.output


def test_inspect_shows_the_phrase_split_play_uses_and_which_phrases_are_trained(tmp_path):
    """chord.mid's policies were trained as three one-chord phrases (models/README.md)."""
    trained = run("inspect", EXAMPLES / "chord.mid")
    assert "3 phrases" in trained.output and trained.output.count("own policy") >= 3
    bare = run("inspect", EXAMPLES / "chord.mid", "--models", tmp_path, "--json", tmp_path / "bare.json")
    assert re.search(r"\b1 phrase\b(?!s)", bare.output)  # nothing trained: the default split
    assert "general policy (phrase not trained)" in bare.output and "own policy" not in bare.output
    # a phrase the store's index gives the general policy (its own policy was set aside) is said so,
    # where inspect called it trained and play played it with the general policy
    (phrase,) = json.loads((tmp_path / "bare.json").read_text())["phrases"]
    (tmp_path / "general-plays.json").write_text(json.dumps({f"{phrase['hash']}-0123456789ab": {"why": "worse"}}))
    judged = run("inspect", EXAMPLES / "chord.mid", "--models", tmp_path)
    assert "general policy (judged better)" in judged.output and "not trained" not in judged.output


def test_inspect_with_transpose_tempo_and_keyboard_options(tmp_path):
    low = write_midi(Piece((Note(0, 48, 1, 80, 2), Note(1, 50, 2, 80, 3)), bpm=60), tmp_path / "low.mid")
    own = run("inspect", low)  # no keys named: the piece's own octaves, said in one line
    assert own.exit_code == 0 and "lie off the default keys C4-B5 (24 keys): played on C3-B4 (24 keys)" in " ".join(
        own.output.split()
    )
    assert "playable on C3-B4" in own.stdout
    assert_one_line_error(run("inspect", low, "--lowest-note", "C5"), "--transpose 24")  # keys named: as named
    assert run("inspect", low, "--transpose", "12").exit_code == 0
    assert run("inspect", low, "--lowest-note", "C3").exit_code == 0
    slow = run("inspect", low, "--lowest-note", "C3", "--tempo", "30")
    assert "4.00 s at 30 bpm" in slow.output


def test_thumb_option_enables_finger_one(tmp_path):
    path = write_midi(Piece((Note(0, 60, 1, 80, 1),)), tmp_path / "thumb.mid")
    assert_one_line_error(run("inspect", path, "--hand-model", "allegro"), "--thumb")
    assert run("inspect", path, "--thumb").exit_code == 0
    assert run("inspect", path).exit_code == 0  # (no hand named: the pianist's, for a fingering with the thumb)


def test_track_option(tmp_path):
    midi = mido.MidiFile(type=1)
    # (tracks named for hands, or notes too far apart for one hand, would play both hands)
    for name, pitch in (("one", 60), ("two", 48)):
        track = mido.MidiTrack(
            [
                mido.MetaMessage("track_name", name=name),
                mido.Message("note_on", note=pitch, velocity=80),
                mido.Message("note_off", note=pitch, time=480),
            ]
        )
        midi.tracks.append(track)
    midi.save(tmp_path / "two.mid")
    # one hand cannot play it (C3 is off its keyboard): the fingering planner gives both hands a note
    both = run("inspect", tmp_path / "two.mid")
    assert both.exit_code == 0, both.output
    text = " ".join(both.stdout.split())
    assert "right hand: 1 note, C4-C4" in text and "left hand: 1 note, C3-C3" in text, text
    assert run("inspect", tmp_path / "two.mid", "--track", "one").exit_code == 0
    two = run("inspect", tmp_path / "two.mid", "--track", "two")  # C3 alone: on its own octaves
    assert two.exit_code == 0 and "played on C3-B4" in " ".join(two.output.split())
    assert_one_line_error(
        run("inspect", tmp_path / "two.mid", "--track", "two", "--keys", "12"), "outside the keyboard", "C3"
    )
    assert_one_line_error(run("inspect", tmp_path / "two.mid", "--track", "9"), "no track '9'")


def write_bytes(tmp_path, name, data):
    path = tmp_path / name
    path.write_bytes(data)
    return path


@pytest.mark.parametrize("command", ["inspect", "score"])
def test_bad_files_answer_with_one_line(tmp_path, scale_file, command):
    not_midi = write_bytes(tmp_path, "x.mid", b"RIFF....WAVEfmt ")
    truncated = write_bytes(tmp_path, "t.mid", scale_file.read_bytes()[:30])
    empty = tmp_path / "empty.mid"
    mido.MidiFile(tracks=[mido.MidiTrack([mido.MetaMessage("track_name", name="x")])]).save(empty)
    for bad, words in (
        (not_midi, "not a MIDI file"),
        (truncated, "truncated"),
        (empty, "no notes"),
        (tmp_path / "missing.mid", "no such file"),
    ):
        args = ("inspect", bad) if command == "inspect" else ("score", scale_file, bad)
        assert_one_line_error(run(*args), str(bad.name) if words != "no such file" else "missing.mid", words)


def test_polyphony_and_missing_fingers(tmp_path):
    # fingered with a finger twice in one chord, which one hand cannot hold: both hands play it (it
    # was refused, "4 notes sound at once"), the marks kept where they play them (the fingering is
    # both hands', not one hand's to be fingered anew)
    fingered = Piece(tuple(Note(0, p, 1, 80, f) for p, f in zip((60, 64, 67, 71), (2, 3, 4, 4))))
    for model in ((), ("--hand-model", "allegro")):
        kept = run("inspect", write_midi(fingered, tmp_path / "f.mid"), *model)
        assert kept.exit_code == 0 and "`pianobot play` plays both" in " ".join(kept.stdout.split()), kept.output
        said = " ".join(kept.stderr.split())
        assert "its notes are given to both hands" in said and "fingered anew" not in said, said
    # unfingered, one hand's reading refuses it: both hands play it, neither given more than its fingers
    both = run("inspect", write_midi(fingered.without_fingering(), tmp_path / "c.mid"))
    assert both.exit_code == 0, both.output
    text = " ".join(both.stdout.split())
    assert "`pianobot play` plays both" in text, text
    # (no hand model named: the pianist's hands, whose one hand spans less than this seventh)
    assert "c.mid: one hand cannot play it (the chord C4 E4 G4 B4 at 0.000 s spans" in " ".join(both.stderr.split())
    assert re.search(r"right hand: [1-3] notes?, .* left hand: [1-3] notes?, ", text), text
    allegro = run("inspect", tmp_path / "c.mid", "--hand-model", "allegro")
    assert allegro.exit_code == 0, allegro.output
    assert "c.mid: one hand cannot play it (4 notes sound at once at 0.000 s" in " ".join(allegro.stderr.split())
    assert re.search(r"right hand: [123] notes?, .* left hand: [123] notes?, ", " ".join(allegro.stdout.split()))
    little = write_midi(Piece((Note(0, 60, 1, 80, 5),)), tmp_path / "l.mid")
    assert_one_line_error(run("inspect", little, "--hand-model", "allegro"), "fingered 5 (little)")
    # (no hand model named: a fingering with a finger the Allegro-like hand lacks is the pianist's hand's)
    assert "with fingers 1 (thumb), 2 (index), 3 (middle), 4 (ring), 5 (little)" in " ".join(
        run("inspect", little).stdout.split()
    )


def test_sidecar_problems(tmp_path, scale):
    song = write_midi(scale, tmp_path / "song.mid")
    assert_one_line_error(run("inspect", song, "--fingering", tmp_path / "nope.txt"), "does not exist")
    sidecar_for(song).write_text("//Version: PianoFingering_v170101\n0\t0\t1\tC4\n")
    assert_one_line_error(run("inspect", song), "song_fingering.txt line 2", "needs 8")
    write_pig(scale, sidecar_for(song))
    result = run("inspect", song)
    assert result.exit_code == 0 and "replaces the fingering" in result.output


def test_overlaps_are_a_warning_not_an_error(tmp_path):
    midi = mido.MidiFile(type=1)
    for _ in range(2):
        midi.tracks.append(
            mido.MidiTrack(
                [
                    mido.Message("note_on", note=60, velocity=80, time=0 if not midi.tracks else 240),
                    mido.Message("note_off", note=60, time=480),
                ]
            )
        )
    midi.save(tmp_path / "overlap.mid")
    result = run("inspect", tmp_path / "overlap.mid")
    assert result.exit_code == 0, result.output
    assert "warning:" in result.output and "Traceback" not in result.output


def test_bad_option_values(scale_file, tmp_path):
    assert_one_line_error(run("score", scale_file, scale_file, "--onset-tolerance", "0"), "--onset-tolerance")
    assert_one_line_error(run("score", scale_file, scale_file, "--plot", tmp_path / "x.jpg"), "PNG")
    assert_one_line_error(run("inspect", scale_file, "--lowest-note", "X9"), "not a pitch")
    assert_one_line_error(run("inspect", scale_file, "--tempo", "0"), "--tempo")
    assert_one_line_error(run("score", scale_file, scale_file, "--json", tmp_path / "no" / "r.json"), "does not exist")


def test_version():
    result = run("--version")
    assert result.exit_code == 0 and result.output.startswith("pianobot ")


def test_play_scripted_writes_a_performance_that_scores_well(tmp_path):
    out = tmp_path / "out.mid"
    result = run(
        "play",
        EXAMPLES / "three-note.mid",
        "-o",
        out,
        "--controller",
        "scripted",
        "--video",
        tmp_path / "out.mp4",
        "--wav",
        tmp_path / "out.wav",
    )
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert report["f1"] >= 0.95 and report["velocity_mae"] <= 10 and report["performer"] == "scripted pianist"
    from pianobot.music.midi_io import read_midi, write_midi

    played = read_midi(out)
    assert [n.pitch for n in played] == [60, 62, 64] and played.has_fingering
    assert read_midi(write_midi(played, tmp_path / "again.mid")) == played
    scored = run("score", out, EXAMPLES / "three-note.mid", "--json", tmp_path / "s.json")
    assert json.loads((tmp_path / "s.json").read_text())["f1"] == report["f1"]
    import imageio.v2 as imageio
    from scipy.io import wavfile

    rate, audio = wavfile.read(tmp_path / "out.wav")
    assert rate == 22050 and len(audio) > 3 * rate and np.abs(audio).max() > 1000  # three seconds of sound
    assert "audio written" in result.output
    frames = imageio.get_reader(tmp_path / "out.mp4").count_frames()
    assert frames > 50  # one frame per control step
    assert scored.exit_code == 0


def test_play_bad_requests_answer_with_one_line(tmp_path, scale):
    song = EXAMPLES / "one-note.mid"
    assert_one_line_error(run("play", song, "-o", tmp_path / "out.wav"), "*.mid")
    assert_one_line_error(run("play", song, "-o", song), "overwrite")
    assert_one_line_error(
        run("play", song, "-o", tmp_path / "x.mid", "--controller", "robot"), "'--controller'", "'robot'"
    )
    assert_one_line_error(run("play", song, "-o", tmp_path / "x.mid", "--video", tmp_path / "v.gif"), "*.mp4")
    assert_one_line_error(run("play", song, "-o", tmp_path / "x.mid", "--wav", tmp_path / "a.mp3"), "*.wav")
    assert_one_line_error(
        run("play", song, "-o", tmp_path / "x.mid", "--hand", "right", "--track", "0"), "--track or --hand"
    )
    assert_one_line_error(run("play", song, "-o", tmp_path / "x.mid", "--quantize", "eighth"), "--quantize eighth")
    assert not (tmp_path / "x.mid").exists()


def test_play_gui_without_a_display_is_refused(tmp_path, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    assert_one_line_error(run("play", EXAMPLES / "one-note.mid", "-o", tmp_path / "x.mid", "--gui"), "display")


def test_play_random_controller(tmp_path):
    result = run("play", EXAMPLES / "one-note.mid", "-o", tmp_path / "r.mid", "--controller", "random", "--seed", "3")
    assert result.exit_code == 0, result.output
    assert json.loads((tmp_path / "r.report.json").read_text())["performer"] == "random actions"


def test_train_bad_requests_answer_with_one_line(tmp_path):
    song = EXAMPLES / "one-note.mid"
    assert_one_line_error(run("train"), "--task")
    assert_one_line_error(run("train", song, "--task", "one-note"), "not both")
    assert_one_line_error(run("train", "--task", "sonata"), "'--task'", "'sonata'", "'melody'")
    line = assert_one_line_error(run("train", song, "--steps", "100"), "--steps 100: SAC learns only after its 15000")
    assert "--exploration-steps" in line and "--learner dagger" in line
    assert_one_line_error(run("train", song, "--steps", "-5"), "'--steps'", "greater than or equal to 1")
    assert_one_line_error(
        run("train", song, "--control", "joint"), "'--control'", "'joint'", "'velocity', 'position', 'torque'"
    )
    assert_one_line_error(run("train", song, "--reward", "cubic"), "'--reward'", "'linear', 'squared', 'wasserstein'")
    assert_one_line_error(run("train", song, "--explore", "wild"), "'--explore'", "'wild'", "'scripted'")
    assert_one_line_error(
        run("train", song, "--explore", "scripted", "--control", "torque"), "needs velocity or position control"
    )
    assert_one_line_error(run("train", song, "--until-f1", "1.5"), "note F1 to stop at", "1.5")
    (tmp_path / "file").write_text("x")
    assert_one_line_error(run("train", song, "--models", tmp_path / "file"), "is a file")


def test_train_then_skip(tmp_path):
    args = (
        "train",
        EXAMPLES / "one-note.mid",
        "--steps",
        "80",
        "--exploration-steps",
        "40",
        "--no-tactile",
        "--models",
        tmp_path,
    )
    first = run(*args)
    assert first.exit_code == 0, first.output
    folders = [d for d in tmp_path.iterdir() if d.is_dir()]
    assert len(folders) == 1 and (folders[0] / "policy.safetensors").exists()
    manifest = json.loads((folders[0] / "manifest.json").read_text())
    assert (
        manifest["piece"] == "one-note.mid"
        and manifest["steps"] == 80
        and manifest["config"]["env"]["tactile"] is False
    )
    assert (
        manifest["evaluation"]["step"] == 80 and "kept" in first.output
    )  # the summary says which evaluation's policy was kept
    second = run(*args)
    assert second.exit_code == 0 and "already trained" in second.output and "training 0 policies" in second.output
    third = run(*args, "--force")
    assert "training 1 policy" in third.output


def test_train_a_task_family_evaluates_on_many_instances(tmp_path):
    """A task's instances all differ: its evaluation plays TASK_EVAL_EPISODES of them, not a phrase's 3."""
    from pianobot.learn.train import TASK_EVAL_EPISODES

    result = run(
        "train",
        "--task",
        "one-note",
        "--steps",
        "60",
        "--exploration-steps",
        "30",
        "--no-tactile",
        "--models",
        tmp_path,
    )
    assert result.exit_code == 0, result.output
    (folder,) = [d for d in tmp_path.iterdir() if d.is_dir()]
    manifest = json.loads((folder / "manifest.json").read_text())
    assert folder.name.startswith("task-one-note-") and manifest["target"] == "one-note"
    assert manifest["config"]["eval_episodes"] == TASK_EVAL_EPISODES > 3


def test_play_sac_without_policies_names_the_phrase_and_the_train_command(tmp_path):
    """The trained policies play by default: without them (and without the general policy), one
    line says where it looked and how to get them or what else to do."""
    result = run(
        "play", EXAMPLES / "three-note.mid", "-o", tmp_path / "x.mid", "--models", tmp_path, "--policy", "none"
    )
    assert_one_line_error(
        result,
        "phrase 0 (C4 D4 E4)",
        str(tmp_path),
        "pianobot train",
        "--models",
        "--policy scripted",
        "--controller scripted",
    )
    assert not (tmp_path / "x.mid").exists()


def test_play_sac_composes_trained_and_fallback_phrases(tmp_path):
    """Phrase 0 has a (barely) trained policy, phrase 1 none, and no general policy
    fits its environment: --policy scripted plays it and says so."""
    one = EXAMPLES / "one-note.mid"
    trained = run(
        "train", one, "--steps", "60", "--exploration-steps", "30", "--no-tactile", "--models", tmp_path / "models"
    )
    assert trained.exit_code == 0, trained.output
    note = Piece((Note(0.0, 64, 1.0, 80, 3), Note(3.0, 67, 4.0, 70, 4)), bpm=60)  # phrase 0 = one-note.mid
    song = write_midi(note, tmp_path / "song.mid")
    args = (
        "play",
        song,
        "-o",
        tmp_path / "out.mid",
        "--controller",
        "sac",
        "--models",
        tmp_path / "models",
        "--phrase-notes",
        "1",
    )
    assert_one_line_error(run(*args), "phrase 1 (G4)")
    result = run(*args, "--policy", "scripted")
    assert result.exit_code == 0, result.output
    assert "phrase 1: scripted pianist" in result.output
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert report["phrases"]["0"].startswith("own policy ") and report["phrases"]["1"] == "scripted pianist"
    played = [n for n in read_played(tmp_path / "out.mid") if n.pitch == 67 and n.onset >= 2.0]
    assert played and played[0].finger == 4  # the scripted pianist took over and played phrase 1


def test_play_composes_policies_with_different_agent_settings(tmp_path):
    """Each phrase's policy is loaded with its own manifest's agent settings: one that reads the
    score window (as older policies do) beside one that does not."""
    from dataclasses import replace

    from pianobot.agent import store
    from pianobot.agent.config import SACConfig
    from pianobot.env.piano import EnvConfig
    from pianobot.learn.config import TrainConfig
    from pianobot.learn.train import train_policy
    from pianobot.music.phrases import split_phrases

    piece = Piece((Note(0.0, 64, 1.0, 80, 3), Note(3.0, 67, 4.0, 70, 4)), bpm=60)
    song = write_midi(piece, tmp_path / "song.mid")
    base = TrainConfig(
        steps=40,
        eval_episodes=1,
        sac=SACConfig(exploration_steps=20, batch_size=16, hidden=16),
        env=EnvConfig(tactile=False),
    )
    for phrase, reads_score in zip(split_phrases(piece, 1), (True, False)):
        config = replace(base, sac=replace(base.sac, score_input=reads_score))
        train_policy(phrase.piece(), config, store.model_dir(tmp_path / "models", phrase.hash, config))
    result = run("play", song, "-o", tmp_path / "out.mid", "--models", tmp_path / "models", "--phrase-notes", "1")
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert report["phrases"]["0"].startswith("own policy ") and report["phrases"]["1"].startswith("own policy ")


def read_played(path):
    from pianobot.music.midi_io import read_midi

    return read_midi(path).notes


def test_sections_hand_over_after_the_last_strike():
    from pianobot.env.piano import EnvConfig, PianoEnv
    from pianobot.music.phrases import split_phrases
    from pianobot.perform.compose import CompositionalController
    from pianobot.perform.plan import assign

    piece = Piece((Note(0.0, 60, 0.5, 80, 2), Note(0.5, 62, 1.0, 80, 3), Note(1.0, 64, 1.5, 80, 4)), bpm=60)
    phrases = split_phrases(piece, 1)
    env = PianoEnv(piece=piece, config=EnvConfig(tactile=False))
    composed = CompositionalController(env, assign(phrases, Path("/nonexistent"), fallback=True))
    firsts = [s.first_step for s in composed.sections]
    # the previous phrase keeps the hand through its last note's onset tolerance (50 ms = 1 step):
    # control passes 2 steps after that note's onset step (lead-in 20 steps, notes 10 steps apart)
    assert firsts == [0, 22, 32]
    assert composed.section_at(21).phrases[0].index == 0 and composed.section_at(22).phrases[0].index == 1
    window = composed.sections[1].rows(0, env.horizon)
    assert window[30][:, 0].nonzero()[0].tolist() == [2]  # phrase 1 sees only its own note (D4)
    assert window[:, :, 0].nonzero()[0].tolist() == list(range(30, 40))  # in its own steps only
    assert composed.sections[1].tensor.shape[0] <= 12  # its memory is its own length, not the piece's

    fast = Piece((Note(0.0, 60, 0.1, 80, 2), Note(0.1, 62, 0.2, 80, 3)), bpm=60)  # onsets 2 steps apart
    env = PianoEnv(piece=fast, config=EnvConfig(tactile=False))
    composed = CompositionalController(env, assign(split_phrases(fast, 1), Path("/nonexistent"), fallback=True))
    assert [s.first_step for s in composed.sections] == [0, 21]  # at the latest one step before the next onset (22)


def test_train_options_reach_the_stored_configuration(tmp_path):
    result = run(
        "train",
        EXAMPLES / "one-note.mid",
        "--steps",
        "50",
        "--exploration-steps",
        "25",
        "--no-tactile",
        "--control",
        "torque",
        "--reward",
        "wasserstein",
        "--no-fingering-gate",
        "--joints",
        "mcp,pip",
        "--explore",
        "uniform",
        "--seed",
        "3",
        "--models",
        tmp_path,
    )
    assert result.exit_code == 0, result.output
    config = json.loads(next(tmp_path.glob("*/manifest.json")).read_text())["config"]
    assert config["seed"] == 3 and config["explore"] == "uniform" and config["sac"]["exploration_steps"] == 25
    assert config["env"]["world"]["control"] == "torque" and config["env"]["actuated"] == ["mcp", "pip"]
    assert config["env"]["reward"]["kind"] == "wasserstein" and config["env"]["reward"]["fingering_gate"] is False
    assert_one_line_error(run("train", EXAMPLES / "one-note.mid", "--joints", "elbow"), "--joints elbow")


def test_train_fingering_options_are_distinct(tmp_path):
    """--fingering names a PIG file (as for every reading command); the reward's gate is --fingering-gate."""
    from pianobot.music.pig import write_pig

    piece = Piece((Note(0.0, 64, 1.0, 80, None),), bpm=60)
    song = write_midi(piece, tmp_path / "song.mid")
    pig = write_pig(Piece((Note(0.0, 64, 1.0, 80, 4),), bpm=60), tmp_path / "fingers.txt")
    result = run(
        "train",
        song,
        "--fingering",
        pig,
        "--no-fingering-gate",
        "--steps",
        "40",
        "--exploration-steps",
        "20",
        "--no-tactile",
        "--models",
        tmp_path / "m",
    )
    assert result.exit_code == 0, result.output
    manifest = json.loads(next((tmp_path / "m").glob("*/manifest.json")).read_text())
    assert [n["finger"] for n in manifest["target"]] == [4] and manifest["config"]["env"]["reward"][
        "fingering_gate"
    ] is False
    help_text = run("train", "--help").output
    assert help_text.count("--fingering ") == 1 and "--fingering-gate" in help_text


def test_train_workers_train_phrases_in_parallel(tmp_path):
    song = write_midi(Piece((Note(0.0, 60, 0.5, 80, 2), Note(2.0, 67, 2.5, 70, 4)), bpm=60), tmp_path / "two.mid")
    result = run(
        "train",
        song,
        "--phrase-notes",
        "1",
        "--steps",
        "40",
        "--exploration-steps",
        "20",
        "--no-tactile",
        "--workers",
        "2",
        "--models",
        tmp_path / "models",
    )
    assert result.exit_code == 0, result.output
    manifests = [json.loads(p.read_text()) for p in (tmp_path / "models").glob("*/manifest.json")]
    assert sorted(m["phrases"] for m in manifests) == [[0], [1]] and all(m["steps"] == 40 for m in manifests)
    # play finds the split the policies were trained for without being told --phrase-notes 1
    played = run("play", song, "-o", tmp_path / "out.mid", "--models", tmp_path / "models")
    assert played.exit_code == 0, played.output
    assert "2 phrases of at most 1 note:" in played.output
    phrases = json.loads((tmp_path / "out.report.json").read_text())["phrases"]
    assert sorted(phrases) == ["0", "1"] and all(v.startswith("own policy ") for v in phrases.values())


MODELS = Path(__file__).parent.parent / "models"


def _committed_examples() -> list[Path]:
    """Examples whose every phrase has a policy committed in models/."""
    from pianobot.music.load import load_piece
    from pianobot.perform.compose import missing_phrases, trained_split

    return [
        p
        for p in sorted(EXAMPLES.glob("*.mid"))
        if "performed" not in p.stem and not missing_phrases(MODELS, trained_split(MODELS, load_piece(p), None))
    ]


def test_the_committed_policies_cover_the_papers_five_tasks_and_a_melody():
    assert {"one-note", "three-note", "six-note", "rhythmic", "chord", "twinkle"} <= {
        p.stem for p in _committed_examples()
    }


@pytest.mark.parametrize("song", _committed_examples(), ids=lambda p: p.stem)
def test_committed_policies_play_their_example_from_a_fresh_checkout(tmp_path, song):
    """models/ holds policies trained by the commands in models/README.md; `play --controller sac`
    uses them and reaches note F1 >= 0.9 on average over three hand starts."""
    f1s = []
    for seed in (0, 1, 2):
        result = run("play", song, "-o", tmp_path / "o.mid", "--controller", "sac", "--models", MODELS, "--seed", seed)
        assert result.exit_code == 0, result.output
        report = json.loads((tmp_path / "o.report.json").read_text())
        judged = "played both ways" in result.output  # (a policy of another simulator: judge.perform_judged)
        assert judged or all(source.startswith("own policy ") for source in report["phrases"].values())
        f1s.append(report["f1"])
    assert sum(f1s) / 3 >= 0.9, f1s


@pytest.mark.parametrize("song", ["mary", "ode-to-joy", "c-major-scale"])
def test_the_committed_general_policy_plays_unseen_songs_from_any_folder(tmp_path, song, monkeypatch):
    """No phrase of these songs has a policy of its own: `play`, run from another folder, uses the
    general policy that ships in the package (trained by `--learner dagger`, models/README.md) for
    every one, and says so."""
    monkeypatch.chdir(tmp_path)
    result = run("play", EXAMPLES / f"{song}.mid", "-o", tmp_path / "o.mid")
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "o.report.json").read_text())
    assert report["phrases"] and all(s.startswith("general policy task-melody-") for s in report["phrases"].values())
    assert report["general_policy"]["path"].endswith(tuple(p.name for p in PACKAGED.glob("task-melody-*")))
    assert report["f1"] >= 0.9, report["f1"]


def test_inspect_says_when_the_file_changes_tempo(tmp_path):
    """The line's tempo is the file's first; a file that changes tempo says so (and JSON lists them)."""
    from conftest import midi_file, off, on

    notes = [m for i in range(4) for m in ((480 * i, on(60 + 2 * i)), (480 * i + 400, off(60 + 2 * i)))]
    song = midi_file(tmp_path / "t.mid", [("melody", notes)], tempo_events=((0, 600_000), (960, 500_000)))
    result = run("inspect", song, "--json", tmp_path / "i.json")
    assert result.exit_code == 0, result.output
    assert "s at 100 bpm, then 1 other tempo (100-120 bpm);" in " ".join(result.stdout.split())
    assert json.loads((tmp_path / "i.json").read_text())["tempi"] == [100.0, 120.0]
    steady = run("inspect", song, "--tempo", "90")
    assert "s at 90 bpm;" in " ".join(steady.stdout.split())


def test_a_suggested_transposition_counts_the_one_already_given(tmp_path):
    """After --transpose 12 the hint named the shift from the moved notes (-24), not the one to give (-12)."""
    high = write_midi(Piece((Note(0, 84, 1, 80, 2), Note(1, 86, 2, 80, 3)), bpm=60), tmp_path / "high.mid")
    for command in ("inspect", "finger"):
        extra = ("-o", tmp_path / "f.mid") if command == "finger" else ()
        assert_one_line_error(run(command, high, "--keys", "24", *extra), "use --transpose -12")
        assert_one_line_error(run(command, high, "--keys", "24", "--transpose", "12", *extra), "use --transpose -12")
    line = assert_one_line_error(
        run("play", high, "--keys", "24", "--transpose", "12", "-o", tmp_path / "o.mid"), "use --transpose -12"
    )
    assert "-24" not in line


def test_a_melody_written_legato_plays_as_one_hand(tmp_path):
    """Each note of a scale up and down lasting 0.1 s into the next (a player's legato, as a
    recording writes it): the planner refused it (E4 still down when F4 is struck, and no fingering
    of three fingers goes on from there) and advised --hand; each note now ends where the next
    begins, as with --hand, and the melody plays and scores whole."""
    pitches = [60, 62, 64, 65, 67, 65, 64, 62, 60]
    notes = tuple(Note(0.667 * i, p, 0.667 * i + 0.767, 80) for i, p in enumerate(pitches))
    song = write_midi(Piece(notes, bpm=90), tmp_path / "legato.mid")
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--json", tmp_path / "r.json")
    assert result.exit_code == 0, result.output
    assert json.loads((tmp_path / "r.json").read_text())["f1"] == 1.0
    scored = run("score", tmp_path / "out.mid", song, "--json", tmp_path / "s.json")
    assert scored.exit_code == 0 and json.loads((tmp_path / "s.json").read_text())["f1"] == 1.0
    from pianobot.music.load import end_legato

    ended = end_legato(Piece(notes))
    assert [n.offset for n in ended.notes[:-1]] == [n.onset for n in notes[1:]]
    assert ended.notes[-1] == notes[-1]  # (the last overlaps nothing)
    held = Piece((Note(0.0, 60, 2.0, 80), Note(0.5, 64, 1.0, 80)))  # a note held under another: kept
    assert end_legato(held) is held


def test_score_says_which_option_a_low_score_may_lack(tmp_path):
    """A performance played with --transpose 5 (or --tempo 40) scored without it read 0 of 14 notes
    and said nothing; score now names the option. A performance scored as played gets no hint."""
    song = EXAMPLES / "twinkle.mid"
    for option, value, words in (("--transpose", "5", "lie 5 semitones above"), ("--tempo", "40", "lasts 24.0 s")):
        played = tmp_path / f"{option[2:]}.mid"
        assert run("play", song, "-o", played, "--controller", "scripted", option, value, "--quiet").exit_code == 0
        bare = " ".join(run("score", played, song, "--no-notes").output.split())
        assert words in bare and f"played with {option}" in bare, bare
        same = run("score", played, song, option, value, "--no-notes").output
        assert "score it with the same option" not in same
    # a performance played as written, scored with --transpose: the hint names no option, not its negative
    played = tmp_path / "plain.mid"
    assert run("play", song, "-o", played, "--controller", "scripted", "--quiet").exit_code == 0
    wrong = " ".join(run("score", played, song, "--transpose", "2", "--no-notes").output.split())
    assert "lie 2 semitones below the reference's as read with --transpose 2" in wrong
    assert "played without --transpose, score it without" in wrong, wrong
    slow = " ".join(run("score", played, song, "--tempo", "40", "--no-notes").output.split())
    assert (
        "read with --tempo 40: if the piece was played at another tempo, score it with that one, or without --tempo"
        in slow
    ), slow
