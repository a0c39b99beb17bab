"""Property-based tests of the model store: whatever a manifest or a policy file holds, loading a
policy gives one that acts (finite actions in [-1, 1]) or a one-line PianobotError; never another
exception, never an unpickled object."""

import json
import shutil
import tempfile
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pianobot.agent import store
from pianobot.agent.policy import load_policy, policy_configs
from pianobot.env.piano import PianoEnv
from pianobot.errors import PianobotError
from pianobot.music.piece import Note, Piece

MODELS = Path(__file__).parent.parent / "models"
SOURCE = next(d for d in sorted(MODELS.iterdir()) if (d / store.MANIFEST_FILE).exists())
PHRASE = Piece((Note(0.0, 64, 0.5, 80, 3),), bpm=60)
MODELS_FUZZ = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])

json_values = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**40), 2**40),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.lists(st.integers(-5, 300), max_size=3),
    st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
)


def paths(node, prefix=()):
    """Every (key path) in a nested dict of the manifest's config."""
    for key, value in node.items():
        yield prefix + (key,)
        if isinstance(value, dict):
            yield from paths(value, prefix + (key,))


CONFIG_PATHS = sorted(paths(json.loads((SOURCE / store.MANIFEST_FILE).read_text())["config"]))


def load_and_act(folder: Path) -> None:
    try:
        env_config, _ = policy_configs(folder)
        env = PianoEnv(piece=PHRASE, config=env_config)
    except PianobotError as e:
        assert "\n" not in str(e)
        return
    try:
        policy = load_policy(folder, env)
        observation, _ = env.reset(seed=0)
        action = policy.act(observation)
        assert action.shape == env.action_space.shape and np.all(np.abs(action) <= 1)
    except PianobotError as e:
        assert "\n" not in str(e)
    finally:
        env.close()


def copy_of_the_model() -> Path:
    folder = Path(tempfile.mkdtemp()) / SOURCE.name
    shutil.copytree(SOURCE, folder)
    return folder


@MODELS_FUZZ
@given(where=st.sampled_from(CONFIG_PATHS), value=json_values)
def test_any_value_anywhere_in_a_manifest_loads_or_is_one_line(where, value):
    folder = copy_of_the_model()
    try:
        manifest = json.loads((folder / store.MANIFEST_FILE).read_text())
        node = manifest["config"]
        for key in where[:-1]:
            node = node[key]
        node[where[-1]] = value
        (folder / store.MANIFEST_FILE).write_text(json.dumps(manifest))
        load_and_act(folder)
    finally:
        shutil.rmtree(folder.parent)


@MODELS_FUZZ
@given(data=st.data())
def test_a_corrupted_policy_file_loads_or_is_one_line(data):
    folder = copy_of_the_model()
    try:
        path = folder / store.POLICY_FILE
        raw = bytearray(path.read_bytes())
        for _ in range(data.draw(st.integers(1, 8))):
            # the header (its first bytes: length, then JSON) or anywhere in the weights
            at = data.draw(st.one_of(st.integers(0, 200), st.integers(0, len(raw) - 1)))
            raw[at] = data.draw(st.integers(0, 255))
        if data.draw(st.booleans()):
            raw = raw[: data.draw(st.integers(0, len(raw)))]  # cut short
        path.write_bytes(bytes(raw))
        load_and_act(folder)
    finally:
        shutil.rmtree(folder.parent)


def test_a_manifest_asking_for_a_window_loads_without_one(tmp_path):
    """`world.gui` true in a manifest (fuzzing found it) once opened a PyBullet GUI connection,
    which waits for ever where there is no display: a stored file never opens a window."""
    folder = tmp_path / SOURCE.name
    shutil.copytree(SOURCE, folder)
    manifest = json.loads((folder / store.MANIFEST_FILE).read_text())
    manifest["config"]["env"]["world"]["gui"] = True
    (folder / store.MANIFEST_FILE).write_text(json.dumps(manifest))
    env_config, _ = policy_configs(folder)
    assert env_config.world.gui is False
    load_and_act(folder)
