"""A finger-shared policy widened to a hand with a thumb (pianobot/agent/widen.py)."""

import numpy as np
import pytest
import torch

from pianobot.agent.actors import FingerActor, FingerLayout
from pianobot.agent.config import SACConfig
from pianobot.agent.store import read_manifest
from pianobot.agent.widen import WIDENED, context_sources, widen_actor, widen_policy
from pianobot.errors import PianobotError
from pianobot.music.instrument import HandSpec

JOINTS, WIDTH = 4, 6
OLD, NEW = FingerLayout(3, JOINTS, WIDTH), FingerLayout(4, JOINTS, WIDTH)
SLOTS = [1, 2, 3]  # fingers 2, 3, 4 of a hand with fingers 1-4
PER_FINGER = 2  # actions per finger


def actor(layout: FingerLayout, seed: int) -> FingerActor:
    torch.manual_seed(seed)
    vector = 2 + layout.fingers * (2 * JOINTS + WIDTH)
    return FingerActor(vector, 0, layout.fingers * PER_FINGER + 1, layout, SACConfig(actor="fingers", hidden=32))


def blocks(vector: np.ndarray, layout: FingerLayout) -> list[np.ndarray]:
    """The vector's wrist, then each finger's joints, speeds and target (by finger)."""
    out, base = [vector[:2]], 2
    for width in (JOINTS, JOINTS, WIDTH):
        out.extend(vector[base + f * width : base + (f + 1) * width] for f in range(layout.fingers))
        base += layout.fingers * width
    return out


def test_context_sources_put_each_old_value_in_its_fingers_new_place_and_leave_the_new_finger_empty():
    sources = context_sources(OLD, NEW, SLOTS, rest=0)
    old = np.arange(2 + 3 * (2 * JOINTS + WIDTH), dtype=float)
    new = np.where(sources >= 0, old[np.maximum(sources, 0)], -1.0)
    old_blocks, new_blocks = blocks(old, OLD), blocks(new, NEW)
    assert np.array_equal(new_blocks[0], old_blocks[0])  # the wrist
    for part in range(3):  # joints, speeds, targets
        assert np.all(new_blocks[1 + part * 4] == -1)  # the thumb's: nothing
        for i, slot in enumerate(SLOTS):
            assert np.array_equal(new_blocks[1 + part * 4 + slot], old_blocks[1 + part * 3 + i])
    with pytest.raises(PianobotError, match="different joints or targets"):
        context_sources(OLD, FingerLayout(4, JOINTS, WIDTH + 1), SLOTS, rest=0)
    # the keys' values, where observed, come after the fingers', in the same order
    keyed = context_sources(OLD, NEW, SLOTS, rest=3)
    assert list(keyed[-3:]) == [len(old) + k for k in range(3)] and list(keyed[:-3]) == list(sources)


def test_a_widened_actor_moves_the_fingers_it_knew_and_the_wrist_as_before_whatever_the_new_finger_does():
    old, new = actor(OLD, 0), actor(NEW, 1)
    tensors = {f"actor.{k}": v for k, v in old.state_dict().items()}
    widened = widen_actor(tensors, OLD, NEW, SLOTS, rest=0)
    new.load_state_dict({k[len("actor.") :]: v for k, v in widened.items()})
    rng = np.random.default_rng(0)
    for _ in range(5):
        vector = rng.normal(size=2 + 3 * (2 * JOINTS + WIDTH)).astype(np.float32)
        wide = np.zeros(2 + 4 * (2 * JOINTS + WIDTH), np.float32)
        sources = context_sources(OLD, NEW, SLOTS, rest=0)
        wide[sources >= 0] = vector[sources[sources >= 0]]
        wide[sources < 0] = rng.normal(size=int((sources < 0).sum()))  # the thumb's joints, speeds, target
        with torch.no_grad():
            mean_old, _ = old.heads(None, torch.from_numpy(vector)[None])
            mean_new, _ = new.heads(None, torch.from_numpy(wide)[None])
        by_finger_old = mean_old[0, :-1].reshape(3, PER_FINGER)
        by_finger_new = mean_new[0, :-1].reshape(4, PER_FINGER)
        assert torch.allclose(by_finger_new[SLOTS], by_finger_old, atol=1e-5)
        assert torch.allclose(mean_new[0, -1], mean_old[0, -1], atol=1e-5)  # the wrist
    # the thumb is a finger like the others: its index weights are their mean
    first = widened["actor.finger.0.weight"]
    own = 2 + 2 * JOINTS + WIDTH
    assert torch.allclose(first[:, own], tensors["actor.finger.0.weight"][:, own : own + 3].mean(dim=1))


def test_widen_policy_refuses_what_it_cannot_widen(tmp_path):
    with pytest.raises(PianobotError, match="holds no manifest.json"):
        widen_policy(tmp_path / "none", tmp_path / "out", (1, 2, 3, 4))


def test_the_packaged_parts_policy_widens_to_a_hand_with_its_thumb(tmp_path):
    from pianobot.agent.general import PACKAGED
    from pianobot.agent.policy import load_policy, policy_configs, policy_target
    from pianobot.agent.tasks import make_env

    source = next(
        p for p in sorted(PACKAGED.glob("task-parts-*")) if policy_configs(p)[0].world.hand.spec.fingers == (2, 3, 4)
    )
    folder = widen_policy(source, tmp_path / "wide", (1, 2, 3, 4))
    env, _ = policy_configs(folder)
    assert env.world.hand.spec.fingers == (1, 2, 3, 4)
    manifest = read_manifest(folder)
    assert manifest["kept"] == WIDENED and manifest["widened"]["fingers_before"] == [2, 3, 4]
    instance = make_env(policy_target(folder), env)
    try:
        agent = load_policy(folder, instance)  # the widened tensors fit the hand with a thumb
        observation, _ = instance.reset(seed=0)
        assert instance.action_space.contains(agent.act(observation).astype(np.float32))
    finally:
        instance.close()
    with pytest.raises(PianobotError, match="already holds a policy"):
        widen_policy(source, folder, (1, 2, 3, 4))
    with pytest.raises(PianobotError, match="do not add"):
        widen_policy(source, tmp_path / "same", (2, 3, 4))
    with pytest.raises(PianobotError, match="the allegro hand has fingers 1,2,3,4"):
        widen_policy(source, tmp_path / "five", (2, 3, 4, 5))
    assert not (tmp_path / "same").exists() and not (tmp_path / "five").exists()


def test_the_widen_command_says_bad_input_in_one_line_and_exits_2(tmp_path, capsys):
    from pianobot.agent.widen import main

    for argv, said in (
        ([str(tmp_path), str(tmp_path / "out"), "--fingers", "1,two"], "--fingers 1,two: give finger numbers"),
        ([str(tmp_path / "none"), str(tmp_path / "out")], "holds no manifest.json"),
        ([str(tmp_path), str(tmp_path / "out"), "--hand-model", "shadow"], "invalid choice: 'shadow'"),
    ):
        with pytest.raises(SystemExit) as exit:
            main(argv)
        assert exit.value.code == 2
        assert said in capsys.readouterr().err.strip().splitlines()[-1]


def test_the_packaged_melody_policy_widens_to_the_pianist_s_five_fingers(tmp_path):
    """``--hand-model`` gives another body the same weights: the Allegro-like hand's three-finger
    policy starts a five-finger pianist's hand, whose world and joints it then drives."""
    from pianobot.agent.general import PACKAGED
    from pianobot.agent.policy import load_policy, policy_configs, policy_target
    from pianobot.agent.tasks import make_env
    from pianobot.sim.hand import default_fingers, hand_config

    source = next(PACKAGED.glob("task-melody-*"))
    folder = widen_policy(source, tmp_path / "pianist", (1, 2, 3, 4, 5), "pianist")
    env, _ = policy_configs(folder)
    assert env.world.hand == hand_config(default_fingers("pianist"))  # the pianist's body, not the Allegro's
    widened = read_manifest(folder)["widened"]
    assert (widened["hand_model_before"], widened["hand_model"]) == ("allegro", "pianist")
    instance = make_env(policy_target(folder), env)
    try:
        agent = load_policy(folder, instance)
        observation, _ = instance.reset(seed=0)
        action = agent.act(observation)
        assert action.shape == (5 * 4 + 1,) and instance.action_space.contains(action.astype(np.float32))
    finally:
        instance.close()
    same = widen_policy(source, tmp_path / "same-fingers", (2, 3, 4), "pianist")  # another body, the same fingers
    assert policy_configs(same)[0].world.hand.spec == HandSpec((2, 3, 4), model="pianist")
    with pytest.raises(ValueError, match="choose one of allegro, pianist"):
        widen_policy(source, tmp_path / "bad", (1, 2, 3, 4), "shadow")


def test_the_widen_command_gives_another_body_its_own_fingers_by_default(tmp_path):
    """``--hand-model pianist`` without ``--fingers``: the pianist's default five, not 1,2,3,4."""
    from pianobot.agent.general import PACKAGED
    from pianobot.agent.widen import main

    main([str(next(PACKAGED.glob("task-melody-*"))), str(tmp_path / "five"), "--hand-model", "pianist"])
    widened = read_manifest(tmp_path / "five")["widened"]
    assert widened["fingers"] == [1, 2, 3, 4, 5] and widened["hand_model"] == "pianist"
