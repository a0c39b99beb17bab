"""DAgger: the cloning step learns the teacher's actions, rounds gather what the teacher labels,
an interrupted run resumes exactly, and its policy plays, fine-tunes and is chosen like SAC's."""

import json
from dataclasses import replace

import numpy as np
import pytest
import torch

from pianobot.agent import store
from pianobot.agent.config import SACConfig
from pianobot.agent.general import PACKAGED
from pianobot.agent.imitation import Imitation
from pianobot.agent.policy import load_policy, make_agent
from pianobot.agent.store import config_hash
from pianobot.env.piano import EnvConfig
from pianobot.learn.config import DaggerConfig, TrainConfig, config_from_manifest
from pianobot.learn.dagger import dagger_policy
from pianobot.learn.jobs import learner
from pianobot.learn.train import Progress, make_env, train_policy
from pianobot.music.piece import Note, Piece
from pianobot.pianist.scripted import ScriptedPianist

PHRASE = Piece((Note(0.0, 64, 0.5, 80, 3),), bpm=60)  # a one-note phrase: 35 steps an episode
NETS = SACConfig(batch_size=32, buffer_size=1000, hidden=32, score_features=16, exploration_steps=60)


def small(**changes) -> TrainConfig:
    config = TrainConfig(
        learner="dagger",
        steps=200,
        eval_episodes=1,
        sac=NETS,
        dagger=DaggerConfig(round_steps=70, updates_per_step=0.5, batch_size=32),
        env=EnvConfig(tactile=True),
    )
    return replace(config, **changes)


def test_the_learner_setting_picks_the_loop():
    assert learner(TrainConfig()) is train_policy and learner(small()) is dagger_policy
    with pytest.raises(ValueError, match="learner"):
        TrainConfig(learner="ppo")
    torque = EnvConfig(world=replace(EnvConfig().world, control="torque"))
    with pytest.raises(ValueError, match="velocity or position"):
        TrainConfig(learner="dagger", explore="prior", env=torque)
    TrainConfig(learner="dagger", steps=100)  # SAC's exploration steps need not fit a DAgger run's


def test_a_cloning_step_moves_the_policy_towards_the_teachers_actions():
    torch.manual_seed(0)
    env = make_env(PHRASE, EnvConfig(tactile=True))
    agent = make_agent(env, NETS)
    teacher, observations = ScriptedPianist(EnvConfig(tactile=True)), []
    observation, _ = env.reset(seed=0)
    teacher.reset()
    for _ in range(20):
        observations.append((*agent.split(observation), teacher.act(observation)))
        observation, *_ = env.step(observations[-1][2])
    batch = {
        "vector": torch.from_numpy(np.stack([o[0] for o in observations])),
        "tactile": torch.from_numpy(np.stack([o[1] for o in observations])),
        "expert": torch.from_numpy(np.stack([o[2] for o in observations]).astype(np.float32)),
    }
    imitation = Imitation(agent, 1e-3)
    first = imitation.update(batch)["cloning_loss"]
    for _ in range(300):
        last = imitation.update(batch)["cloning_loss"]
    assert last < first / 10 and agent.updates == 301
    acted = agent.act_batch(batch["vector"].numpy(), batch["tactile"].numpy())
    assert np.abs(acted - batch["expert"].numpy()).mean() < 0.05  # the deterministic action is the taught one
    saved = imitation.tensors()  # Adam's moments, for checkpoints, load back into a fresh optimiser
    again = Imitation(agent, 1e-3)
    again.load_tensors(saved)
    assert all(torch.equal(saved[k], v) for k, v in again.tensors().items()) and saved.keys() == again.tensors().keys()


def test_a_run_learns_in_rounds_and_stores_a_policy_without_critic(tmp_path):
    seen: list[Progress] = []
    manifest = dagger_policy(PHRASE, small(), tmp_path / "m", seen.append)
    rounds = [e for e in manifest["evaluations"] if "round" in e]
    assert [e["round"] for e in rounds] == [1, 2, 3]  # 70 steps a round, ending at an episode's end: 3 rounds
    assert all(e["step"] % 35 == 0 and e["step"] >= 70 * e["round"] for e in rounds)
    assert manifest["steps"] == rounds[-1]["step"] >= 200 and manifest["config"]["learner"] == "dagger"
    # each round ends in half an update per step gathered
    assert manifest["updates"] == sum(
        round(0.5 * (b["step"] - a)) for a, b in zip([0] + [e["step"] for e in rounds], rounds)
    )
    assert manifest["evaluation"] in [{k: v for k, v in e.items() if k != "round"} for e in rounds]
    assert sum(p.finished for p in seen) == 1 and [p.eval_f1 is not None for p in seen].count(True) == 3
    folder = tmp_path / "m"
    assert store.is_trained(folder) and not (folder / store.CRITIC_FILE).exists()
    assert not (folder / store.CHECKPOINT_DIR).exists()
    env = make_env(PHRASE, small().env)
    observation, _ = env.reset(seed=0)
    assert load_policy(folder, env).act(observation).shape == (13,)


def test_the_first_round_is_the_teachers_and_later_ones_mostly_the_policys(tmp_path):
    """Round 0's actions are the teacher's plus the exploration noise; with teacher_share 0 every
    later episode is the policy's, whose actions differ from the labels."""
    config = small(dagger=DaggerConfig(round_steps=70, updates_per_step=0.5, batch_size=32, teacher_share=0.0))
    dagger_policy(PHRASE, config, tmp_path / "m", stop_after=100)
    (data,) = (tmp_path / "m" / store.CHECKPOINT_DIR).glob("*/buffer")
    actions, labels = np.load(data / "action.npy"), np.load(data / "expert.npy")
    assert len(actions) == 140 and np.load(data / "demo.npy").all()  # every step has a teacher's label
    first, second = np.abs(actions[:70] - labels[:70]).mean(), np.abs(actions[70:] - labels[70:]).mean()
    assert first < 0.2 and second > first  # the untrained policy strays further than the noisy teacher


def test_an_interrupted_run_resumes_to_the_same_policy(tmp_path):
    torch.set_num_threads(1)
    config = small()
    dagger_policy(PHRASE, config, tmp_path / "straight")
    assert dagger_policy(PHRASE, config, tmp_path / "resumed", stop_after=100) == {"interrupted_at": 140}
    assert store.checkpoint_state(tmp_path / "resumed")["rounds"] == 2
    dagger_policy(PHRASE, config, tmp_path / "resumed")
    a = store.load_tensors(tmp_path / "straight" / store.POLICY_FILE)
    b = store.load_tensors(tmp_path / "resumed" / store.POLICY_FILE)
    assert a.keys() == b.keys() and all(torch.equal(a[k], b[k]) for k in a)
    manifests = [json.loads((tmp_path / f / store.MANIFEST_FILE).read_text()) for f in ("straight", "resumed")]
    assert manifests[0]["evaluations"] == manifests[1]["evaluations"]


def test_finish_ends_an_interrupted_run_at_its_checkpoint_with_the_best_policy_so_far(tmp_path):
    """TrainConfig.finish (`train --finish`): the same run, resumed, trains no further: the best policy
    its checkpoint kept is stored, the manifest says the steps it took, and the checkpoint goes.
    Without a checkpoint the option changes nothing: the run trains all its steps."""
    torch.set_num_threads(1)
    config = small()
    assert config_hash(replace(config, finish=True)) == config_hash(config)  # the same folder
    folder = tmp_path / "m"
    assert dagger_policy(PHRASE, config, folder, stop_after=100) == {"interrupted_at": 140}
    tensors, state, _ = store.load_checkpoint(folder)
    best = {k[len("best.") :]: v for k, v in tensors.items() if k.startswith("best.")}
    manifest = dagger_policy(PHRASE, replace(config, finish=True), folder)
    assert manifest["steps"] == 140 < config.steps and manifest["evaluation"] == state["best"]
    assert [e["step"] for e in manifest["evaluations"]] == [70, 140]  # no round after the checkpoint's
    stored = store.load_tensors(folder / store.POLICY_FILE)
    assert stored.keys() == best.keys() and all(torch.equal(stored[k], best[k]) for k in best)
    assert store.is_trained(folder) and not (folder / store.CHECKPOINT_DIR).exists()
    fresh = dagger_policy(PHRASE, replace(config, finish=True), tmp_path / "fresh")
    assert fresh["steps"] >= config.steps  # (rounds of 70 steps: 210)


def test_a_start_policy_that_already_plays_the_phrase_costs_one_evaluation(tmp_path):
    dagger_policy(PHRASE, small(), tmp_path / "general")
    config = small(from_general=True, finetune_until_f1=1e-9)  # any F1 above 0 is "good enough"
    manifest = dagger_policy(PHRASE, config, tmp_path / "tuned", start=tmp_path / "general")
    assert manifest["start"]["path"] == str(tmp_path / "general") and manifest["evaluations"][0]["step"] == 0
    assert (manifest["steps"] == 0) == (manifest["evaluations"][0]["f1"] > 0)  # stopped at once, or trained on
    if manifest["steps"] == 0:  # the start plays it: no copy of it is stored
        assert manifest["kept"] == "start" and not (tmp_path / "tuned").exists()
    else:  # trained on: a policy is stored when an evaluation beat the start's
        trained = manifest["evaluation"]["step"] > 0
        assert (manifest["kept"] == "trained") == trained == store.is_trained(tmp_path / "tuned")
    # SAC fine-tunes from a cloned policy too: fresh Q heads, the cloned actor and encoder
    sac = replace(config, learner="sac", finetune_until_f1=1.0, steps=100)
    manifest = train_policy(PHRASE, sac, tmp_path / "sac", start=tmp_path / "general")
    assert manifest["start"]["critic"] is False and manifest["evaluations"][0]["step"] == 0


def test_the_dagger_settings_name_a_dagger_runs_folder_and_not_a_sac_runs():
    rounds = DaggerConfig(round_steps=1000)
    assert store.config_hash(TrainConfig()) == store.config_hash(TrainConfig(dagger=rounds))  # SAC: unused
    dagger = TrainConfig(learner="dagger")
    assert store.config_hash(dagger) != store.config_hash(TrainConfig())
    assert store.config_hash(dagger) != store.config_hash(replace(dagger, dagger=rounds))


def test_the_fingers_actor_reads_each_fingers_own_values_and_learns_by_imitation(tmp_path):
    """SACConfig(actor='fingers'): finger f's actions come from finger f's joints, speeds and
    target (one network for all fingers), the run stores it, and the store gives it back."""
    torch.manual_seed(0)
    fingers = replace(NETS, actor="fingers")
    env = make_env(PHRASE, EnvConfig(tactile=True, actuated=("mcp", "pip")))  # 2 joints a finger, then the wrist
    agent = make_agent(env, fingers)
    assert not agent.actor.reads_features
    first, own = agent.actor.finger[0], 2 + 2 * 4 + 6  # wrist, a finger's 4 angles and 4 speeds, its target
    with torch.no_grad():  # blind the shared network to the finger's index and the whole-vector context
        first.weight[:, own:] = 0
    observation, _ = env.reset(seed=0)
    vector, tactile = agent.split(observation)
    slices = [(2, 4), (14, 4), (26, 6)]  # (start, width per finger): angles, speeds, targets (after the wrist)
    nudged = vector.copy()
    nudged[26 + 6 : 26 + 12] += 0.5  # finger 1's target
    swapped = vector.copy()  # fingers 0 and 1 trade their values
    for start, width in slices:
        swapped[start : start + width] = vector[start + width : start + 2 * width]
        swapped[start + width : start + 2 * width] = vector[start : start + width]
    before, after, traded = agent.act_batch(np.stack([vector, nudged, swapped]), np.stack([tactile] * 3))
    changed = np.abs(after - before) > 1e-6
    assert changed[2:4].all() and not changed[[0, 1, 4, 5]].any()  # finger 1's two joints move, fingers 0 and 2 do not
    # one network plays every finger: with their values traded, fingers 0 and 1 trade their actions
    assert np.allclose(traded[0:2], before[2:4], atol=1e-6) and np.allclose(traded[2:4], before[0:2], atol=1e-6)
    assert np.allclose(traded[4:6], before[4:6], atol=1e-6)

    manifest = dagger_policy(PHRASE, small(sac=fingers), tmp_path / "m")
    assert manifest["config"]["sac"]["actor"] == "fingers" and manifest["updates"] > 0
    stored = load_policy(tmp_path / "m", make_env(PHRASE, small().env))
    assert type(stored.actor).__name__ == "FingerActor"
    assert store.config_hash(small()) != store.config_hash(small(sac=fingers))  # its own folder
    with pytest.raises(ValueError, match="finger target"):
        make_agent(make_env(PHRASE, EnvConfig(target_observations=False)), fingers)


def test_the_hold_guard_plays_the_policys_episodes_and_names_its_own_folder(tmp_path, monkeypatch):
    """With ``hold_guard`` every step the policy plays goes through the hold guard and is stepped as
    the guard passes it on (the teacher's episodes are not guarded); without it the guard is not
    made. A run with it has a folder of its own; without it, the folder every DAgger run had before
    (the packaged policies' names still match their manifests)."""
    from pianobot.perform import guard

    proposed, passed = [], []
    act = guard.HoldGuard.act

    def spy(self, observation):
        proposed.append(self.policy.act(observation).copy())
        passed.append(act(self, observation))
        return passed[-1]

    monkeypatch.setattr(guard.HoldGuard, "act", spy)
    held = Piece((Note(0.0, 64, 1.0, 80, 3),), bpm=60)  # a held note: the guard's teacher moves the holding finger
    settings = DaggerConfig(round_steps=70, updates_per_step=0.5, batch_size=32, teacher_share=0.0)
    config = small(dagger=settings)
    dagger_policy(held, config, tmp_path / "plain", stop_after=100)
    assert passed == []
    dagger_policy(
        held, replace(config, dagger=replace(settings, hold_guard=True)), tmp_path / "guarded", stop_after=100
    )
    (data,) = (tmp_path / "guarded" / store.CHECKPOINT_DIR).glob("*/buffer")
    actions = np.load(data / "action.npy")
    teacher = len(actions) - len(passed)  # round 0 is the teacher's (whole episodes), round 1 the policy's
    assert teacher >= 70 and len(passed) >= 70
    np.testing.assert_allclose(actions[teacher:], np.array(passed), atol=1e-6)  # stepped as the guard passed them
    assert any(np.abs(a - b).max() > 1e-3 for a, b in zip(proposed, passed))  # it took over the holding finger

    guarded = replace(config, dagger=replace(settings, hold_guard=True))
    assert store.config_hash(guarded) != store.config_hash(config)
    for folder in PACKAGED.glob("task-parts-*"):
        manifest = json.loads((folder / store.MANIFEST_FILE).read_text())
        assert folder.name.endswith(store.config_hash(config_from_manifest(manifest)))
