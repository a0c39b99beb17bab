"""Tactile images: zero when free, deeper with force, and exact against PyBullet's own ray casts."""

import numpy as np
import pytest

from pianobot.env.piano import EnvConfig, PianoEnv
from pianobot.music.piece import Note, Piece
from pianobot.pianist.scripted import ScriptedPianist
from pianobot.sim.bullet import p
from pianobot.sim.tactile import TactileConfig, TactileRenderer, pool, to_uint8


@pytest.fixture(scope="module")
def pressing():
    """A world in which the middle finger holds E4 down (scripted pianist), and a renderer."""
    config = EnvConfig(tactile=False, random_start=False)
    env = PianoEnv(piece=Piece((Note(0.0, 64, 2.0, 90, 3),)), config=config)
    pianist = ScriptedPianist(config)
    observation, _ = env.reset(seed=0)
    for _ in range(env.lead_steps + 6):
        observation, *_ = env.step(pianist.act(observation))
    renderer = TactileRenderer(TactileConfig(), config.world.hand.geometry, env.world.boxes)
    yield env, renderer
    env.close()


def sensor_state(env, finger):
    angles, _ = env.world.key_state()
    position, rotation = env.world.link_pose(env.world.tip_links[finger])
    return position, rotation, angles, env.world.tip_forces()[finger]


def test_image_shape_and_range(pressing):
    env, renderer = pressing
    image = renderer.image(*sensor_state(env, 3))
    assert image.shape == (60, 80) and image.dtype == np.float32
    assert 0.0 <= image.min() and image.max() <= 1.0


def test_pressing_finger_sees_an_imprint_and_free_fingers_see_nothing(pressing):
    env, renderer = pressing
    forces = env.world.tip_forces()
    assert forces[3] > 0 and forces[2] == forces[4] == 0
    assert renderer.image(*sensor_state(env, 3)).max() > 0.1
    assert renderer.image(*sensor_state(env, 2)).max() == 0
    assert renderer.image(*sensor_state(env, 4)).max() == 0


def test_more_force_gives_a_deeper_and_wider_imprint(pressing):
    env, renderer = pressing
    position, rotation, angles, _ = sensor_state(env, 3)
    light = renderer.image(position, rotation, angles, 0.5)
    firm = renderer.image(position, rotation, angles, 3.0)
    assert firm.max() > light.max()
    assert (firm > 0).sum() > (light > 0).sum()
    assert np.all(firm >= light)


def test_ray_cast_agrees_with_pybullet_ray_test(pressing):
    """The NumPy slab test against the key boxes, checked with Bullet's own rayTestBatch."""
    env, renderer = pressing
    position, rotation, angles, _ = sensor_state(env, 3)
    reach = 0.02
    ours = renderer.distances(position, rotation, angles, max_range=reach).ravel()
    starts, direction = renderer.rays(position, rotation)
    results = p.rayTestBatch(starts.tolist(), (starts + direction * reach).tolist(), physicsClientId=env.world.client)
    theirs = np.array([r[2] * reach if r[0] in env.world.keys else np.inf for r in results])
    on_gel = renderer.on_gel.ravel()
    # compare where both see a key and the ray does not start inside one (Bullet ignores those)
    both = on_gel & np.isfinite(ours) & np.isfinite(theirs) & (ours > 0)
    assert both.sum() > 100
    assert np.abs(ours[both] - theirs[both]).max() < 2e-4  # Bullet keeps a small collision margin
    # every ray on which Bullet sees a key first, we see one too (Bullet may see the hand's own
    # fingertip first on the others: the rays start inside the tip)
    assert np.isfinite(ours[on_gel & np.isfinite(theirs)]).all()


def test_pooling_and_uint8():
    images = np.random.default_rng(0).random((2, 3, 60, 80)).astype(np.float32)
    pooled = pool(images, 15, 20)
    assert pooled.shape == (2, 3, 15, 20)
    assert pooled[1, 2, 0, 0] == pytest.approx(images[1, 2, :4, :4].mean())
    assert to_uint8(np.array([0.0, 0.5, 1.0])).tolist() == [0, 128, 255]
    with pytest.raises(ValueError):
        pool(images, 7, 20)
