"""The performance plan (who plays each stretch) and fine-tuning that never makes a piece worse."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from conftest import run

import pianobot
from pianobot.agent import store
from pianobot.agent.general import GENERAL_KEY, PACKAGED
from pianobot.agent.policy import policy_configs
from pianobot.env import VERSION
from pianobot.errors import PianobotError
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.phrases import DEFAULT_MAX_NOTES, split_phrases
from pianobot.music.piece import Note, Piece
from pianobot.perform.plan import Player, Stretch, passed_over, plan_performance

ROOT = Path(__file__).parent.parent
MODELS = ROOT / "models"
EXAMPLES = ROOT / "examples" / "midi"


def test_the_packaged_general_policy_is_found_from_any_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # no models/ here: only the policy that ships with pianobot
    piece = pianobot.load_piece(EXAMPLES / "mary.mid")
    plan = plan_performance(piece)
    (stretch,) = plan.stretches  # one section: every phrase, no hand-over to itself
    assert stretch.player is Player.GENERAL and PACKAGED in stretch.policy.resolve().parents
    assert stretch.policy.name.startswith(GENERAL_KEY) and len(stretch.phrases) == len(plan.phrases) > 1
    assert plan.performer == "general policy" and plan.to_dict()["general_policy"]["sha256"]


def test_a_plan_names_each_phrases_own_policy_and_says_who_played(tmp_path):
    piece = pianobot.load_piece(EXAMPLES / "twinkle.mid")  # its three phrases have committed policies
    plan = plan_performance(piece, models=MODELS)
    assert [s.player for s in plan.stretches] == [Player.OWN] * 3 and plan.performer == "own policies"
    assert plan.general is None and "general_policy" not in plan.to_dict()

    mary = pianobot.load_piece(EXAMPLES / "mary.mid")
    phrases = split_phrases(mary, DEFAULT_MAX_NOTES)
    general = next(PACKAGED.glob(f"{GENERAL_KEY}-*"))
    models = tmp_path / "models"  # phrase 1 has a policy of its own (in the general policy's environment)
    own = models / f"{phrases[1].hash}-000000000000"
    shutil.copytree(general, own)
    plan = plan_performance(mary, models=models)
    assert [s.player for s in plan.stretches] == [Player.GENERAL, Player.OWN, Player.GENERAL]
    assert plan.player_of(1).policy == own and plan.player_of(0).policy == plan.player_of(2).policy == general
    assert plan.performer == "own policies and general policy"
    assert plan.to_dict()["stretches"][1] == {"phrases": [1], "player": "own policy", "policy": str(own)}
    store.mark_general_plays(models, {own.name: {"why": "a test"}})  # the index says the general policy plays it
    (stretch,) = plan_performance(mary, models=models).stretches
    assert stretch.player is Player.GENERAL and len(stretch.phrases) == len(phrases)


def test_one_player_plans_and_refusals(tmp_path):
    piece = pianobot.load_piece(EXAMPLES / "mary.mid")
    (stretch,) = plan_performance(piece, "scripted").stretches
    assert stretch.player is Player.SCRIPTED and stretch.policy is None
    with pytest.raises(PianobotError, match="controller 'sac2'"):
        plan_performance(piece, "sac2")
    # with the thumb the packaged melody policy (three fingers) does not fit, the packaged thumb's parts policy does
    (stretch,) = plan_performance(piece, models=tmp_path, hand=HandSpec(fingers=(1, 2, 3, 4))).stretches
    assert stretch.player is Player.GENERAL and stretch.policy.name.startswith("task-parts-")
    assert policy_configs(stretch.policy)[0].world.hand.spec == HandSpec(fingers=(1, 2, 3, 4))
    # a hand no packaged policy has: nobody plays, said with where it looked and why the packaged ones do not
    with pytest.raises(
        PianobotError,
        match=r"no general policy plays it \(looked there and in .*policies; the packaged general policies play "
        r"with fingers 2 \(index\), 3 \(middle\), 4 \(ring\) or 1 \(thumb\), 2 \(index\), 3 \(middle\), "
        r"4 \(ring\), 5 \(little\) of the pianist hand or 1 \(thumb\), 2 \(index\), 3 \(middle\), "
        r"4 \(ring\); this piece is read for fingers 1 \(thumb\), 2 \(index\), 3 \(middle\) \(hand.fingers, hand.model\)\)"
        r".*store.models",
    ):
        plan_performance(piece, models=tmp_path, hand=HandSpec(fingers=(1, 2, 3)))
    assert passed_over(KeyboardSpec(), HandSpec()) == ""  # the packaged policies play these: nothing to say
    assert passed_over(KeyboardSpec(48, 36), HandSpec()) == ""  # (wider keyboards too)
    assert passed_over(KeyboardSpec(48, 20), HandSpec()).endswith("read for C3-G4 (20 keys) (keyboard.count)")
    assert plan_performance(piece, models=tmp_path, general=False, fallback=True).performer == "scripted pianist"
    with pytest.raises(ValueError):
        Stretch(tuple(split_phrases(piece, 4)[:2]), Player.OWN, MODELS)  # an own policy plays one phrase


def test_one_call_performs_a_piece_as_play_does(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    piece = Piece((Note(0.0, 60, 0.5, 80, 2), Note(0.5, 62, 1.0, 80, 3), Note(1.0, 64, 2.0, 80, 4)), bpm=60)
    performance = pianobot.play(piece)
    assert performance.plan.performer == "general policy" and performance.report().f1 == 1.0
    report = performance.to_dict()
    assert report["performer"] == "general policy" and report["stretches"][0]["player"] == "general policy"
    assert report["seed"] == 0 and report["f1"] == 1.0


@pytest.mark.slow
def test_a_phrase_policy_that_makes_the_piece_worse_is_not_used(tmp_path):
    """A phrase's own policy that holds the hand still loses its notes in the piece: training
    ends by judging it in the whole piece, and play then lets the general policy play it."""
    import torch

    from pianobot.learn.accept import JUDGE_SEEDS, settle_piece
    from pianobot.perform.judge import play_one_hand as play

    mary = pianobot.load_piece(EXAMPLES / "mary.mid")
    piece = Piece(mary.notes[:12], bpm=mary.bpm)  # two phrases
    phrases = split_phrases(piece, DEFAULT_MAX_NOTES)
    general = next(PACKAGED.glob(f"{GENERAL_KEY}-*"))
    models = tmp_path / "models"
    still = models / f"{phrases[1].hash}-000000000000"  # a policy of its own that outputs nothing
    still.mkdir(parents=True)
    tensors = {k: torch.zeros_like(v) for k, v in store.load_tensors(general / store.POLICY_FILE).items()}
    store.save_tensors(tensors, still / store.POLICY_FILE)
    manifest = json.loads((general / store.MANIFEST_FILE).read_text())
    manifest["simulator"] = VERSION  # (trusted as it is: a policy of another simulator is judged in play itself)
    (still / store.MANIFEST_FILE).write_text(json.dumps(manifest))

    before = [play(piece, models=tmp_path / "none", seed=s).report().f1 for s in JUDGE_SEEDS]
    worse = [play(piece, models=models, seed=s).report().f1 for s in JUDGE_SEEDS]
    assert max(w - b for w, b in zip(worse, before)) < 0  # (the old code played it so)

    verdict = settle_piece(piece, phrases, models, general, started={})
    assert verdict.before == tuple(before) and verdict.after == tuple(before)
    assert 1 in verdict.dropped and not verdict.used
    start, b, w = next((s, b, w) for s, b, w in zip(JUDGE_SEEDS, before, worse) if w < b)
    assert (
        f"from hand start {start} the piece played at note F1 {w:.3f} with it, {b:.3f} without"
        in (store.general_plays(models)[still.name]["why"])
    )
    after = [play(piece, models=models, seed=s).report().f1 for s in JUDGE_SEEDS]
    assert after == before and play(piece, models=models).plan.performer == "general policy"


def test_the_library_names_settings_and_the_command_line_their_options(tmp_path):
    from pianobot.cli.flags import phrase
    from pianobot.errors import SettingError

    piece = pianobot.load_piece(EXAMPLES / "mary.mid")
    with pytest.raises(SettingError) as refused:
        plan_performance(piece, models=tmp_path, general=False)
    assert refused.value.field == "store.models" and "play.fallback scripted" in str(refused.value)
    assert "--models DIR" in phrase(refused.value) and "--policy scripted" in phrase(refused.value)
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / store.MANIFEST_FILE).write_text("{")
    with pytest.raises(SettingError) as unreadable:
        store.read_manifest(tmp_path / "bad")
    assert unreadable.value.field == "jobs.force" and phrase(unreadable.value).endswith(
        "retrain the phrase with --force"
    )


def test_a_phrase_nobody_plays_with_the_general_policy_left_out_says_so(tmp_path):
    """--policy none's refusal not read as if no general policy had been found."""
    piece = pianobot.load_piece(EXAMPLES / "mary.mid")
    with pytest.raises(PianobotError, match=r"the general policy is left out \(play.general\)") as e:
        plan_performance(piece, models=tmp_path, general=False)
    assert "no general policy plays it" not in str(e.value)
    result = run("play", EXAMPLES / "mary.mid", "-o", tmp_path / "out.mid", "--policy", "none", "--models", tmp_path)
    assert "left out (--policy none)" in " ".join(result.stderr.split())
