"""The simulator's version: every stored policy records it, gymnasium's ids carry it, and `play`
judges a phrase policy made on another simulator (or kept beside another general policy) before
trusting it."""

from __future__ import annotations

import json
import shutil
import warnings
from pathlib import Path

import gymnasium
import pytest

import pianobot
from pianobot.agent import store
from pianobot.agent.general import describe
from pianobot.env import VERSION, env_id
from pianobot.errors import PianobotWarning
from pianobot.perform.judge import doubted, play_one_hand
from pianobot.perform.plan import Player, plan_performance

ROOT = Path(__file__).parent.parent
ONE_NOTE = "5755063dc478979f-080639abf744"  # the committed one-note policy: plays its phrase on this simulator
PIECE = ROOT / "examples" / "midi" / "one-note.mid"


def _store(tmp_path: Path, **manifest) -> Path:
    models = tmp_path / "models"
    shutil.copytree(ROOT / "models" / ONE_NOTE, models / ONE_NOTE)
    path = models / ONE_NOTE / store.MANIFEST_FILE
    record = json.loads(path.read_text())
    record.update(manifest)
    for key in [k for k, v in manifest.items() if v is None]:
        record.pop(key)
    path.write_text(json.dumps(record))
    return models


def test_a_manifest_without_the_version_reads_as_the_simulator_of_its_day():
    before = {"format": 2, "config": {"env": {}, "sac": {}}, "saved": "2026-11-24T00:50:44+00:00"}
    after = dict(before, saved="2026-11-25T08:04:21+00:00")
    assert store.upgrade_manifest(before)["simulator"] == 0
    assert store.upgrade_manifest(after)["simulator"] == 1
    assert store.upgrade_manifest({k: v for k, v in before.items() if k != "saved"})["simulator"] == 0
    assert store.upgrade_manifest(dict(after, simulator=0))["simulator"] == 0  # what is recorded stands


def test_a_stored_policy_records_this_simulator(tmp_path):
    store.save_manifest(tmp_path, {"key": "k", "config": {"env": {}, "sac": {}}})
    assert json.loads((tmp_path / store.MANIFEST_FILE).read_text())["simulator"] == VERSION


def test_the_gymnasium_ids_carry_the_version_and_an_older_one_says_which_to_use():
    assert env_id("one-note") == f"pianobot/OneNote-v{VERSION}"
    with pytest.raises(gymnasium.error.DeprecatedEnv, match=f"OneNote-v{VERSION}"):
        gymnasium.make(f"pianobot/OneNote-v{VERSION - 1}")


def test_a_policy_of_this_simulator_plays_as_it_is(tmp_path):
    models = _store(tmp_path, simulator=VERSION)
    piece = pianobot.load_piece(PIECE)
    with warnings.catch_warnings():
        warnings.simplefilter("error", PianobotWarning)
        performance = play_one_hand(piece, models=models)
    assert performance.plan.players == (Player.OWN,)


def test_a_policy_of_another_simulator_is_played_both_ways_and_the_better_kept(tmp_path):
    models = _store(tmp_path, simulator=VERSION - 1)
    piece = pianobot.load_piece(PIECE)
    plan = plan_performance(piece, models=models)
    (folder,) = doubted(plan, models)
    assert f"simulator v{VERSION - 1}" in doubted(plan, models)[folder]
    with pytest.warns(
        PianobotWarning, match=r"played both ways, kept (it|the general policy task-melody-[0-9a-f]+) \(note F1"
    ):
        performance = play_one_hand(piece, models=models)
    own = plan_performance(piece, models=models)
    general = plan_performance(piece, models=models, leave_out=frozenset({ONE_NOTE}))
    assert general.players == (Player.GENERAL,)
    f1s = {p: pianobot.perform_plan(p).report().f1 for p in (own, general)}
    assert performance.report().f1 == max(f1s.values())


def test_a_policy_kept_beside_another_general_policy_is_judged_again(tmp_path):
    models = _store(tmp_path, simulator=VERSION)
    piece = pianobot.load_piece(PIECE)
    general = plan_performance(piece, models=models, leave_out=frozenset({ONE_NOTE})).general
    store.mark_judged(models, {ONE_NOTE: {"path": "elsewhere", "sha256": "0" * 64}})
    plan = plan_performance(piece, models=models)
    assert "another general policy" in doubted(plan, models, general)[models / ONE_NOTE]
    with pytest.warns(PianobotWarning, match="played both ways"):
        play_one_hand(piece, models=models)
    store.mark_judged(models, {ONE_NOTE: describe(general)})  # judged beside the one that plays now
    assert doubted(plan, models, general) == {}


def test_a_policy_loaded_to_play_builds_no_optimiser(tmp_path):
    from pianobot.agent.policy import load_policy, policy_env

    folder = ROOT / "models" / ONE_NOTE
    agent = load_policy(folder, policy_env(folder))
    assert not agent.training and not hasattr(agent, "actor_optimizer") and not hasattr(agent, "target")
    assert not any(p.requires_grad for p in agent.actor.parameters())
