"""The general policy (issue 20, items 2 and 3): `play` uses it for phrases without a policy of
their own, and `train` starts every phrase from it (fine-tuning). A tiny policy trained on the
`melody` family stands in for the real one, which a long run trains."""

import csv
import inspect
import json
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import torch
from conftest import assert_one_line_error, midi_file, off, on, run

from pianobot.agent import store
from pianobot.agent.general import GENERAL_KEY, PACKAGED, describe
from pianobot.cli.app import app
from pianobot.music.midi_io import write_midi
from pianobot.music.piece import Note, Piece

EXAMPLES = Path(__file__).parent.parent / "examples" / "midi"
MODELS = Path(__file__).parent.parent / "models"
ONE_NOTE_POLICY = MODELS / "5755063dc478979f-080639abf744"  # committed: plays one-note.mid at F1 1.0
QUICK = ("--steps", "60", "--exploration-steps", "30", "--no-tactile")


@pytest.fixture(scope="module")
def general(tmp_path_factory) -> Path:
    """A tiny `pianobot train --task melody` policy (without touch), as the store keeps it."""
    models = tmp_path_factory.mktemp("general")
    result = run("train", "--task", "melody", *QUICK, "--models", models)
    assert result.exit_code == 0, result.output
    (folder,) = models.glob(f"{GENERAL_KEY}-*")
    assert (folder / store.CRITIC_FILE).exists()  # it passes its critic on
    return folder


@pytest.fixture
def models(tmp_path, general) -> Path:
    """A model store of this test's own, holding the general policy."""
    shutil.copytree(general, tmp_path / "models" / general.name)
    return tmp_path / "models"


def manifest_of(folder: Path) -> dict:
    return json.loads((folder / store.MANIFEST_FILE).read_text())


def test_train_starts_each_phrase_from_the_general_policy_unless_told_not_to(models):
    """`train song.mid` fine-tunes from the general policy in the store and records it;
    `--no-from-general` trains from scratch; a general policy of other options is refused."""
    general = next(models.glob(f"{GENERAL_KEY}-*"))
    result = run("train", EXAMPLES / "one-note.mid", *QUICK, "--models", models, "--json", "-")
    assert result.exit_code == 0, result.output
    assert "starting every phrase from the general policy" in result.stderr
    (policy,) = json.loads(result.stdout)["policies"]
    manifest = manifest_of(Path(policy["folder"]))
    assert manifest["start"] == describe(general) == policy["start"]
    assert manifest["start"]["sha256"] == store.file_digest(general / store.POLICY_FILE)
    assert manifest["config"]["from_general"] is True
    assert manifest["evaluations"][0]["step"] == 0  # the general policy, evaluated before any step
    assert manifest["steps"] == 60  # (a tiny general policy does not play the phrase: it trained on)
    assert (Path(policy["folder"]) / store.CRITIC_FILE).exists()

    scratch = run("train", EXAMPLES / "one-note.mid", *QUICK, "--models", models, "--no-from-general", "--force")
    assert scratch.exit_code == 0, scratch.output
    assert "starting every phrase" not in scratch.output
    # from scratch, yet judged in the whole piece against the general policy play would use beside it
    assert "playing one-note.mid whole from hand starts 0, 1, 2" in " ".join(scratch.output.split())
    manifest = manifest_of(Path(policy["folder"]))  # the same folder: where a run begins is not in its hash
    assert manifest["start"] is None and manifest["config"]["from_general"] is False
    assert all(e["step"] > 0 for e in manifest["evaluations"])

    # the general policy has no touch; this run would have it
    tactile = run("train", EXAMPLES / "one-note.mid", "--steps", "60", "--exploration-steps", "30", "--models", models)
    # the store's general policy observes no touch; the packaged one does, and fits: the run starts from it
    assert tactile.exit_code == 0 and str(PACKAGED) in " ".join(tactile.output.split()), tactile.output
    wrong = run("train", EXAMPLES / "one-note.mid", *QUICK, "--general-policy", models / "nothing", "--models", models)
    assert_one_line_error(wrong, "--general-policy", "not a trained policy folder")
    unused = run("train", EXAMPLES / "one-note.mid", *QUICK, "--no-from-general", "--general-policy", general)
    assert_one_line_error(unused, "--general-policy", "--no-from-general")


def test_train_task_with_general_policy_continues_that_policy(tmp_path, general):
    """`train --task melody --general-policy P` goes on training P on the family (evaluated
    first, its start recorded); without the option a task family trains from scratch."""
    models = tmp_path / "models"
    result = run("train", "--task", "melody", *QUICK, "--general-policy", general, "--models", models, "--json", "-")
    assert result.exit_code == 0, result.output
    assert "continuing the policy" in result.stderr
    (policy,) = json.loads(result.stdout)["policies"]
    manifest = manifest_of(Path(policy["folder"]))
    assert manifest["start"] == describe(general) and manifest["config"]["from_general"] is True
    assert manifest["evaluations"][0]["step"] == 0
    scratch = run("train", "--task", "melody", *QUICK, "--models", models, "--force")
    assert scratch.exit_code == 0, scratch.output
    assert manifest_of(Path(policy["folder"]))["start"] is None

    # the same options train into the start's own folder: refused before --force deletes it
    files = {f.name: f.read_bytes() for f in general.iterdir() if f.is_file()}
    itself = run(
        "train", "--task", "melody", *QUICK, "--general-policy", general, "--models", general.parent, "--force"
    )
    assert_one_line_error(itself, "--general-policy", "the folder this run trains into", "copy it")
    assert {f.name: f.read_bytes() for f in general.iterdir() if f.is_file()} == files


def test_fine_tuning_begins_with_the_general_weights_and_resumes_knowing_it(tmp_path, general, monkeypatch):
    """The step-0 evaluation is the general policy's own on the phrase (same weights, same figures),
    it is logged, and a run interrupted after it resumes to a manifest that names its start."""
    import pianobot.learn.train as train
    from pianobot.agent.policy import load_policy
    from pianobot.agent.tasks import make_env
    from pianobot.learn.config import config_from_manifest
    from pianobot.learn.log import LOG_FILE
    from pianobot.learn.train import evaluate, train_policy

    phrase = Piece((Note(0.0, 64, 0.5, 80, 3),), bpm=60)
    base = config_from_manifest(store.read_manifest(general))  # its environment and networks
    config = replace(
        base,
        steps=80,
        eval_every=10_000,
        eval_episodes=2,
        checkpoint_every=40,
        from_general=True,
        sac=replace(base.sac, exploration_steps=30, batch_size=16),
    )
    seen = []

    def recording(agent, target, env_config, episodes):
        seen.append({**agent.tensors(with_training_state=False), **agent.critic_tensors()})
        return evaluate(agent, target, env_config, episodes)

    monkeypatch.setattr(train, "evaluate", recording)
    folder = tmp_path / "phrase"
    assert "interrupted_at" in train_policy(phrase, config, folder, stop_after=40, start=general)
    started = {**store.load_tensors(general / store.POLICY_FILE), **store.load_tensors(general / store.CRITIC_FILE)}
    assert seen and set(seen[0]) == set(started) and all(torch.equal(seen[0][k], started[k]) for k in started)
    alone = evaluate(load_policy(general, make_env(phrase, config.env)), phrase, config.env, 2)
    with open(folder / LOG_FILE, newline="") as log:
        first = next(csv.DictReader(log))
    assert first["step"] == "0" and float(first["eval_f1"]) == alone["f1"] and first["return"] == ""

    manifest = train_policy(phrase, config, folder)  # resumed: the checkpoint knows where it began
    assert len(seen) == 2  # the start once, the final evaluation once: no second step-0 evaluation
    assert manifest["evaluations"][0] == {"step": 0, **alone}
    assert manifest["start"] == describe(general) and manifest["config"]["from_general"] is True
    assert manifest["steps"] == 80 and (folder / "learning.png").exists()
    if manifest["evaluation"]["step"] == 0:  # the start played best: it is what was kept
        kept = store.load_tensors(folder / store.POLICY_FILE)
        assert all(torch.equal(kept[k], started[k]) for k in kept)
    assert (manifest["evaluation"]["f1"], manifest["evaluation"]["return"]) >= (alone["f1"], alone["return"])


def test_a_phrase_the_start_policy_already_plays_costs_one_evaluation(tmp_path):
    """The committed one-note policy plays its phrase perfectly: fine-tuning from it stops at
    step 0 and stores nothing: the start policy plays the phrase (``kept: start``)."""
    from pianobot.agent.policy import policy_target
    from pianobot.learn.config import config_from_manifest
    from pianobot.learn.train import train_policy

    trained = config_from_manifest(store.read_manifest(ONE_NOTE_POLICY))  # (with --until-f1 0.95)
    config = replace(trained, from_general=True, until_f1=None)  # fine-tuning's own stop: note F1 1.0
    manifest = train_policy(policy_target(ONE_NOTE_POLICY), config, tmp_path / "m", start=ONE_NOTE_POLICY)
    assert manifest["steps"] == 0 and manifest["updates"] == 0 and manifest["kept"] == "start"
    assert manifest["evaluations"] == [manifest["evaluation"]] and manifest["evaluation"]["f1"] == 1.0
    assert manifest["evaluation"]["step"] == 0 and manifest["start"]["path"] == str(ONE_NOTE_POLICY)
    assert not (tmp_path / "m").exists()  # no copy of the start policy, no log
    # --until-f1 0.95 stops there too; a target it does not reach trains on
    assert config.stop_f1 == 1.0 and replace(config, until_f1=0.95).stop_f1 == 0.95
    assert replace(config, from_general=False).stop_f1 is None


def own_policy(tmp_path: Path, models: Path) -> None:
    """one-note.mid's phrase policy, trained before the general policy came into ``models`` (so
    no whole-piece judgement set it aside: play uses it)."""
    alone = tmp_path / "alone"
    trained = run("train", EXAMPLES / "one-note.mid", *QUICK, "--models", alone)
    assert trained.exit_code == 0 and "judge" not in trained.output, trained.output
    for folder in alone.iterdir():
        shutil.copytree(folder, models / folder.name)


def test_play_uses_a_phrases_own_policy_then_the_general_policy_and_says_so(tmp_path, models):
    general = next(models.glob(f"{GENERAL_KEY}-*"))
    own_policy(tmp_path, models)
    song = write_midi(Piece((Note(0.0, 64, 1.0, 80, 3), Note(3.0, 67, 4.0, 70, 4)), bpm=60), tmp_path / "song.mid")
    args = ("play", song, "-o", tmp_path / "out.mid", "--models", models, "--phrase-notes", "1")
    result = run(*args)  # phrase 0 is one-note.mid's note: its own policy; phrase 1 has none
    assert result.exit_code == 0, result.output
    assert f"phrase 1: general policy {general}" in result.output
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert report["phrases"]["0"].startswith("own policy 5755063dc478979f-")
    assert report["phrases"]["1"] == f"general policy {general.name}"
    assert report["general_policy"] == describe(general)

    # own policy > general policy > scripted fallback: without the general policy, as before
    assert_one_line_error(
        run(*args, "--policy", "none"), "phrase 1 (G4)", "--policy scripted", "pianobot train --task parts"
    )
    fallback = run(*args, "--policy", "scripted")
    assert fallback.exit_code == 0, fallback.output
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert report["phrases"]["1"] == "scripted pianist" and "general_policy" not in report

    # a general policy trained in another environment than the phrase policies is refused
    other = run(*args, "--policy", ONE_NOTE_POLICY)
    assert_one_line_error(other, f"the general policy {ONE_NOTE_POLICY} was trained with env.", "--policy scripted")


def test_train_a_two_hand_file_trains_each_hands_part_and_play_plays_what_was_judged(tmp_path, models):
    """`train` of a two-hand file trains each hand's part as `play` gives it to that hand (the
    left mirrored onto the general policy's keys), from the general policy `play` gives the hand,
    then judges the whole piece, both hands in one simulation: `play` from each judging hand
    start then plays exactly the judged note F1, never below the general policies' alone."""
    general = next(models.glob(f"{GENERAL_KEY}-*"))

    def track(*notes):  # (pitch, start beat, end beat), 0.5 s a beat
        return [event for p, a, b in notes for event in ((a * 480, on(p)), (b * 480, off(p)))]

    right, left = track((72, 0, 1), (74, 1, 2), (76, 2, 3)), track((48, 0, 2), (55, 2, 3))
    song = midi_file(tmp_path / "duet.mid", [("Right Hand", right), ("Left Hand", left)])
    result = run("train", song, *QUICK, "--models", models, "--json", "-", "--hand-model", "allegro")
    assert result.exit_code == 0, result.output
    said = " ".join(result.stderr.split())
    assert f"starting the right hand's phrases from the general policy {general}" in said
    assert f"starting the left hand's phrases from the general policy {general}" in said
    assert "playing duet.mid whole (both hands) from hand starts 0, 1, 2" in said
    summary = json.loads(result.stdout)
    phrases = sorted(p for policy in summary["policies"] for p in policy["phrases"])
    assert phrases == ["left 0", "right 0"]  # (each hand's part is one phrase)
    verdict = summary["piece"]
    assert all(a >= b for a, b in zip(verdict["f1_after"], verdict["f1_before"]))
    for seed, judged in zip(verdict["seeds"], verdict["f1_after"]):
        played = run("play", song, "-o", tmp_path / "out.mid", "--models", models, "--seed", seed, "--json", "-")
        assert played.exit_code == 0, played.output
        assert json.loads(played.stdout)["f1"] == pytest.approx(judged, abs=1e-9)
    used = {key.split()[0] for key in verdict["used"]}
    plans = json.loads((tmp_path / "out.report.json").read_text())["hands"]
    for hand in ("right", "left"):  # a hand whose own policy was kept plays it
        phrase = plans[hand]["plan"]["phrases"]["0"]
        assert phrase.startswith("own policy") == (hand in used), (hand, phrase)


def test_train_a_two_hand_file_with_options_the_packaged_policies_lack_trains_from_scratch(tmp_path):
    """With no general policy in the store, the left hand would start from the packaged parts
    policy; a run whose options it lacks (no touch) passes it over, as play does and as the
    right hand passes over the packaged melody policy: both hands train from scratch."""
    right = [e for p, a in ((72, 0), (74, 1)) for e in ((a * 480, on(p)), ((a + 1) * 480, off(p)))]
    song = midi_file(tmp_path / "duet.mid", [("Right Hand", right), ("Left Hand", [(0, on(48)), (960, off(48))])])
    result = run("train", song, *QUICK, "--models", tmp_path / "models")
    assert result.exit_code == 0, result.output
    said = " ".join(result.output.split())
    for hand in ("right", "left"):
        assert f"no general policy in {tmp_path / 'models'} for the {hand} hand's phrases" in said
    assert "task-parts" not in said and "judge" not in said  # (no general policy fits: nothing to judge against)
    assert len(list((tmp_path / "models").glob("*-*"))) == 2  # one policy per hand's phrase


def test_play_with_only_the_general_policy_plays_every_phrase_in_its_environment(tmp_path, models):
    general = next(models.glob(f"{GENERAL_KEY}-*"))
    result = run("play", EXAMPLES / "three-note.mid", "-o", tmp_path / "out.mid", "--models", models)
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert report["phrases"] == {"0": f"general policy {general.name}"}


def test_the_general_policy_plays_its_consecutive_phrases_as_one_section(tmp_path, models):
    """Phrases without their own policy that follow each other are one stretch for the general policy:
    it sees all their notes, a held one included, on the steps the environment scores them at."""
    from pianobot.agent.policy import policy_configs
    from pianobot.env.piano import PianoEnv
    from pianobot.music.phrases import split_phrases
    from pianobot.perform.compose import CompositionalController
    from pianobot.perform.guard import WristGuard
    from pianobot.perform.plan import assign

    general = next(models.glob(f"{GENERAL_KEY}-*"))
    own_policy(tmp_path, models)
    notes = (
        Note(0.0, 60, 1.0, 80, 2),
        Note(2.5, 62, 2.8, 80, 3),
        Note(3.0, 64, 4.0, 80, 3),  # one-note.mid's note: its own policy
        Note(6.03, 67, 7.53, 70, 2),  # off the 50 ms grid; still held at A4's onset
        Note(7.06, 69, 8.06, 70, 3),
    )
    piece = Piece(notes, bpm=60)
    phrases = split_phrases(piece, 1)
    env = PianoEnv(piece=piece, config=policy_configs(general)[0])
    composed = CompositionalController(env, assign(phrases, models, general), guard=True)
    assert [[p.index for p in s.phrases] for s in composed.sections] == [[0, 1], [2], [3, 4]]
    assert [s.stretch.player.value for s in composed.sections] == ["general policy", "own policy", "general policy"]
    assert composed.sections[0].controller is composed.sections[2].controller  # one guarded policy, loaded once
    assert isinstance(composed.sections[2].controller, WristGuard)
    # the own policy takes over after the tolerance of the section's last onset (D4, step 20 + 50), not C4's
    lead = env.lead_steps
    assert composed.sections[1].first_step == lead + 50 + 2
    last = composed.sections[2]
    steps = slice(last.start, last.start + len(last.tensor))
    assert np.array_equal(last.rows(steps.start, steps.stop), env.score[steps])  # on the scored steps
    assert last.rows(steps.start, steps.stop)[:, :, 0].sum(axis=1).max() == 2  # G4 still sounds at A4's onset
    unguarded = CompositionalController(env, assign(phrases, models, general))  # unguarded by default
    assert not isinstance(unguarded.sections[2].controller, WristGuard)

    song = write_midi(piece, tmp_path / "song.mid")
    args = ("play", song, "-o", tmp_path / "out.mid", "--models", models, "--phrase-notes", "1")
    for guards in ("wrist", "hold"):
        wrist, hold = guards == "wrist", guards == "hold"
        result = run(*args, "--guard", guards)
        assert result.exit_code == 0, result.output
        report = json.loads((tmp_path / "out.report.json").read_text())
        assert [report["phrases"][k].split()[0] for k in "01234"] == ["general"] * 2 + ["own"] + ["general"] * 2
        guard = report["wrist_guard"]
        assert guard == {"on": False, "slowed_steps": 0} if not wrist else guard["on"] is True
        held = report["hold_guard"]
        assert held == {"on": False, "held_finger_steps": 0, "wrist_steps": 0} if not hold else held["on"] is True
        if hold:  # C4 and G4 are held for a second and more: the guard held them
            assert held["held_finger_steps"] > 20


def test_the_options_default_to_the_training_configuration_and_say_what_they_do():
    import typer.main

    from pianobot.learn.config import TrainConfig

    commands = typer.main.get_command(app).commands
    train = {p.name: p for p in commands["train"].params}
    assert train["from_general"].default is TrainConfig.from_general is True
    assert train["until_f1"].default is TrainConfig.until_f1 is None and TrainConfig.finetune_until_f1 == 1.0
    assert "evaluate it before any training step" in train["from_general"].help
    play = {p.name: p.default for p in commands["play"].params}
    from pianobot.cli.commands.play import GUARDS, _players
    from pianobot.perform.plan import PerformancePlan, plan_performance

    defaults = inspect.signature(plan_performance).parameters
    assert play["policy"] == "general" and play["guard"] == "auto"
    assert _players("general", EXAMPLES / "mary.mid", False, "sac") == {
        name: defaults[name].default for name in ("general", "general_policy", "fallback")
    }
    assert GUARDS["auto"] == (PerformancePlan.wrist_guard, PerformancePlan.hold_guard) == (False, None)


def test_a_phrase_trained_from_the_general_policy_takes_its_actor(tmp_path):
    """A general policy with the 'fingers' actor starts phrases with it (--actor left out), in a
    folder its networks name; an --actor that differs from it is refused in one line, an unknown one too."""
    from pianobot.learn.config import config_from_manifest

    models = tmp_path / "models"
    result = run("train", "--task", "melody", *QUICK, "--actor", "fingers", "--models", models)
    assert result.exit_code == 0, result.output
    (general,) = models.glob(f"{GENERAL_KEY}-*")
    assert manifest_of(general)["config"]["sac"]["actor"] == "fingers"
    result = run("train", EXAMPLES / "one-note.mid", *QUICK, "--models", models, "--json", "-")
    assert result.exit_code == 0, result.output
    (policy,) = json.loads(result.stdout)["policies"]
    manifest = manifest_of(Path(policy["folder"]))
    assert manifest["start"]["path"] == str(general) and manifest["config"]["sac"]["actor"] == "fingers"
    assert Path(policy["folder"]).name.endswith(
        store.config_hash(config_from_manifest(manifest))
    )  # its networks name it
    mlp = run("train", EXAMPLES / "one-note.mid", *QUICK, "--actor", "mlp", "--models", models, "--force")
    assert_one_line_error(mlp, "sac.actor fingers", "this run with mlp", "--actor", "--no-from-general")
    kept = (Path(policy["folder"]) / store.POLICY_FILE).read_bytes()
    scratch = run("train", EXAMPLES / "one-note.mid", *QUICK, "--no-from-general", "--models", models, "--json", "-")
    assert scratch.exit_code == 0, scratch.output
    (other,) = json.loads(scratch.stdout)["policies"]  # from scratch, the default actor: a folder of its own
    assert other["trained_now"] and other["folder"] != policy["folder"]
    assert manifest_of(Path(other["folder"]))["config"]["sac"]["actor"] == "mlp"
    assert (Path(policy["folder"]) / store.POLICY_FILE).read_bytes() == kept
    # continuing the fingers policy with its own options would train into its folder: refused
    itself = run("train", "--task", "melody", *QUICK, "--general-policy", general, "--models", models, "--force")
    assert_one_line_error(itself, "--general-policy", "the folder this run trains into")
    assert_one_line_error(
        run("train", "--task", "melody", *QUICK, "--actor", "cnn"), "'--actor'", "'cnn'", "'mlp', 'fingers'"
    )


def test_the_newest_general_policy_is_the_last_trained_not_the_last_checked_out(tmp_path, general):
    """A clone gives every file the checkout's time: which general policy is newest comes from the
    manifests' `saved`, and a manifest without it falls back to its file's time."""
    import os

    from pianobot.agent.general import find_general

    models = tmp_path / "models"
    older, newer = models / f"{GENERAL_KEY}-aaaaaaaaaaaa", models / f"{GENERAL_KEY}-bbbbbbbbbbbb"
    for folder, saved in ((older, "2026-01-01T00:00:00+00:00"), (newer, "2026-06-01T00:00:00+00:00")):
        shutil.copytree(general, folder)
        manifest = manifest_of(folder)
        assert isinstance(manifest["saved"], str)  # every stored policy records it
        (folder / store.MANIFEST_FILE).write_text(json.dumps({**manifest, "saved": saved}))
    os.utime(older / store.MANIFEST_FILE, (2e9, 2e9))  # the older one checked out last
    assert store.find_policies(models, GENERAL_KEY) == [newer, older]
    assert find_general(models) == newer
    legacy = {k: v for k, v in manifest_of(older).items() if k != "saved"}  # written before `saved`: its file's time
    (older / store.MANIFEST_FILE).write_text(json.dumps(legacy))
    os.utime(older / store.MANIFEST_FILE, (2e9, 2e9))  # 2033
    assert store.find_policies(models, GENERAL_KEY) == [older, newer]


def test_a_parts_family_policy_is_a_general_policy_and_the_newest_comes_first(models, general):
    """`train --task parts` policies (hands' parts of two-hand pieces) are general policies too: the newest
    of either family in the store is the one `play` and `train` take, before the packaged one."""
    from pianobot.agent.general import general_candidates

    parts = models / general.name.replace(GENERAL_KEY, "task-parts")
    shutil.copytree(general, parts)
    manifest = manifest_of(parts)
    manifest["saved"] = "2999-01-01T00:00:00+00:00"  # trained after the melody policy
    (parts / store.MANIFEST_FILE).write_text(json.dumps(manifest))
    found = general_candidates(models)
    assert found[:2] == [parts, models / general.name]
    assert all(PACKAGED in f.resolve().parents for f in found[2:]) and len(found) > 2


def test_the_packaged_left_hand_policy_plays_left_hands_only_while_the_store_has_no_general_policy(tmp_path, models):
    """The packaged `task-parts` policy is the left hand's by default, never the general policy of
    one hand; a general policy of the user's own plays both hands (none is offered then), and so
    does the packaged general policy where the left hand's cannot play the keys (fewer than its own)."""
    from pianobot.agent.general import PARTS_KEY, general_candidates, parts_policy
    from pianobot.agent.policy import policy_configs
    from pianobot.music.instrument import HandSpec, KeyboardSpec

    empty = tmp_path / "empty"
    empty.mkdir()
    left = parts_policy(empty)
    assert left is not None and left.name.startswith(f"{PARTS_KEY}-") and PACKAGED in left.resolve().parents
    # the packaged general policy, then the parts policies (for a hand the general policy does not fit: the thumb)
    assert [f.name.split("-")[1] for f in general_candidates(empty)] == ["melody", "parts", "parts", "parts"]
    assert parts_policy(empty, hand=HandSpec((1, 2, 3, 4))) not in (None, left)  # the thumb's
    pianist = parts_policy(empty, hand=HandSpec((1, 2, 3, 4, 5), model="pianist"))  # the pianist's hand's own
    assert pianist is not None and policy_configs(pianist)[0].world.hand.spec.model == "pianist"
    assert parts_policy(empty, hand=HandSpec((2, 3, 4, 5), model="pianist")) is None  # (not without its thumb)
    assert parts_policy(empty, KeyboardSpec()) == left
    assert parts_policy(empty, KeyboardSpec(lowest=36, count=36)) == left  # it plays any wider keyboard
    assert parts_policy(empty, KeyboardSpec(lowest=60, count=12)) is None  # not a narrower one
    assert parts_policy(models) is None  # the user's own general policy plays both hands
    # ... but not one trained for other keys: it plays neither hand here, so the left keeps its own
    (mine,) = models.iterdir()
    manifest = manifest_of(mine)
    manifest["config"]["env"]["world"]["keyboard"]["spec"] = {"lowest": 36, "count": 36}
    (mine / store.MANIFEST_FILE).write_text(json.dumps(manifest))
    assert parts_policy(models, KeyboardSpec()) == left
