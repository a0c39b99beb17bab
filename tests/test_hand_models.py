"""A hand is one model: a new one is a module that makes a HandModel and registers it; the world,
the environment, the fingering planner and the scripted pianist then play with it."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from pianobot.agent import store
from pianobot.env.piano import EnvConfig, PianoEnv
from pianobot.learn.config import TrainConfig
from pianobot.music.instrument import HandSpec
from pianobot.music.piece import Note, Piece
from pianobot.perform.rollout import rollout
from pianobot.pianist.fingering import Planner, plan_fingering
from pianobot.pianist.scripted import ScriptedPianist
from pianobot.sim.hand import ALLEGRO, HAND_MODELS, HandConfig, HandModel, hand_config, register_hand_model
from pianobot.sim.keyboard import KeyboardConfig
from pianobot.sim.world import PianoWorld, WorldConfig

TOY = HandModel(
    name="toy",
    bases=tuple((f, 0.0235 * (f - 3), 0.0) for f in (1, 2, 3, 4, 5)),  # five fingers one white key apart
    finger_sets=((1, 2, 3, 4, 5),),
)
FIVE = HandSpec((1, 2, 3, 4, 5), model="toy")


@pytest.fixture(autouse=True)
def toy_model():
    register_hand_model(TOY)
    yield
    HAND_MODELS.pop("toy", None)


def _melody() -> Piece:
    pitches = (60, 62, 64, 65, 67, 65, 64, 62, 60)  # C D E F G F E D C: one finger a key, no hand move
    return Piece(tuple(Note(0.5 * i, p, 0.5 * i + 0.45, 80) for i, p in enumerate(pitches)), bpm=120)


def test_a_model_with_another_finger_count_builds_its_world_with_a_hand_of_five_fingers():
    world = PianoWorld(WorldConfig(hand=hand_config(FIVE)))
    try:
        assert len(world.finger_joints) == 5 * 4 and sorted(world.hands[0].tips) == [1, 2, 3, 4, 5]
        assert world.min_separation == pytest.approx(2 * (2 * 0.0235 + HandConfig().geometry.link_radius))
    finally:
        world.close()


def test_its_environment_acts_and_observes_every_finger():
    env = PianoEnv(piece=_melody(), config=EnvConfig(world=WorldConfig(hand=hand_config(FIVE)), tactile=True))
    try:
        observation, _ = env.reset(seed=0)
        assert env.action_space.shape == (5 * 4 + 1,)
        assert observation["joints"].shape == (20,) and observation["tactile"].shape[1] == 5
        assert observation["targets"].shape[0] == 5
    finally:
        env.close()


def test_the_planner_fingers_a_melody_with_all_five_and_the_scripted_pianist_plays_it():
    config = EnvConfig(world=WorldConfig(hand=hand_config(FIVE)), tactile=False)
    plan = plan_fingering(_melody(), KeyboardConfig(), config.world.hand)
    fingers = [n.finger for n in plan.piece.notes]
    assert set(fingers) == {1, 2, 3, 4, 5} and not plan.problems  # a five-finger position, no move
    env = PianoEnv(piece=plan.piece, config=config)
    try:
        played = rollout(env, ScriptedPianist(config), seed=0).report()
    finally:
        env.close()
    assert played.f1 == 1.0


def test_the_planner_s_reach_follows_the_model():
    allegro, toy = Planner(hand=HandConfig()), Planner(hand=hand_config(FIVE))
    assert toy.base_x[5] - toy.base_x[1] == pytest.approx(4 * 0.0235)
    assert allegro.base_x == {f: ALLEGRO.base_x(f) for f in ALLEGRO.fingers}


def test_a_hand_config_refuses_fingers_its_model_lacks_and_an_unknown_model():
    with pytest.raises(ValueError, match="allegro hand has fingers 1, 2, 3, 4"):
        HandConfig(spec=HandSpec((2, 3, 5)))
    with pytest.raises(ValueError, match="choose one of"):
        HandConfig(spec=HandSpec((2, 3), model="nobody"))


def test_the_allegro_hand_keeps_its_policies_folders():
    """The model is left out of the configuration's hash for the Allegro-like hand (its folders
    keep their names); another model's runs train into folders of their own."""
    config = TrainConfig()
    toy = replace(config, env=replace(config.env, world=replace(config.env.world, hand=hand_config(FIVE))))
    named = replace(config, env=replace(config.env, world=replace(config.env.world, hand=hand_config(HandSpec()))))
    assert store.config_hash(named) == store.config_hash(config)  # (the Allegro's spec names its model)
    assert store.config_hash(config) != store.config_hash(toy)


THUMBED = HandModel(
    name="thumbed",
    bases=TOY.bases,
    finger_sets=((1, 2, 3, 4, 5),),
    finger_joints=((1, ("abd", "mcp", "pip")),),  # a thumb with three joints, the others four
)


def test_fingers_with_different_joint_counts_act_through_the_finger_shared_actor():
    import torch

    from pianobot.agent.config import SACConfig
    from pianobot.agent.policy import make_agent
    from pianobot.env.piano import finger_counts

    register_hand_model(THUMBED)
    try:
        spec = HandSpec((1, 2, 3, 4, 5), model="thumbed")
        config = EnvConfig(world=WorldConfig(hand=hand_config(spec)), tactile=False)
        assert finger_counts(config) == ((3, 4, 4, 4, 4), (3, 4, 4, 4, 4))
        env = PianoEnv(piece=_melody(), config=config)
        try:
            observation, _ = env.reset(seed=0)
            assert env.action_space.shape == (3 + 4 * 4 + 1,) and observation["joints"].shape == (19,)
            torch.manual_seed(0)
            agent = make_agent(env, SACConfig(actor="fingers", score_input=False, hidden=32))
            action = agent.act(observation)
            assert action.shape == env.action_space.shape and np.all(np.abs(action) <= 1.0)
            env.step(action)
            # the thumb's three actions come from the first three of the shared head's outputs
            assert agent.actor.kept.tolist()[:4] == [0, 1, 2, 4]
        finally:
            env.close()
        with pytest.raises(ValueError, match="not every finger"):
            ScriptedPianist(config)
    finally:
        HAND_MODELS.pop("thumbed", None)
