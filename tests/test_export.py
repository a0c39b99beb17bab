"""`pianobot export`: a stored policy as ONNX acts as pianobot's policy does, in onnxruntime."""

import json
from pathlib import Path

import numpy as np
import pytest

import pianobot

ROOT = Path(__file__).parent.parent
ort = pytest.importorskip("onnxruntime")


def test_an_exported_policy_acts_as_the_stored_one(tmp_path):
    from pianobot.agent.export import export_onnx

    phrase = pianobot.split_phrases(pianobot.load_piece(ROOT / "examples" / "midi" / "twinkle.mid"))[1]
    folder = next((ROOT / "models").glob(f"{phrase.hash}-*"))
    path = export_onnx(folder, tmp_path / "policy.onnx")
    session = ort.InferenceSession(str(path))
    assert [i.name for i in session.get_inputs()] == ["vector", "tactile"]
    meta = session.get_modelmeta().custom_metadata_map
    assert json.loads(meta["pianobot_manifest"])["key"] == phrase.hash
    env_config, _ = pianobot.policy_configs(folder)
    env = pianobot.PianoEnv(piece=phrase.piece(), config=env_config)
    policy = pianobot.load_policy(folder, env)
    observation, _ = env.reset(seed=3)
    for _ in range(20):
        vector, tactile = policy.split(observation)
        batch = {"vector": np.stack([vector, vector]), "tactile": np.stack([tactile, tactile])}  # any batch size
        action = session.run(None, batch)[0]
        assert action.shape == (2, 13) and np.allclose(action[0], policy.act(observation), atol=1e-5)
        observation, *_ = env.step(action[0])
    env.close()


def test_the_export_command(tmp_path):
    from typer.testing import CliRunner

    from pianobot.cli.app import app

    folder = next(f for f in sorted((ROOT / "models").iterdir()) if (f / "manifest.json").exists())
    result = CliRunner().invoke(app, ["export", str(folder), "-o", str(tmp_path / "p.onnx")])
    assert result.exit_code == 0, result.output
    assert ort.InferenceSession(str(tmp_path / "p.onnx")).get_outputs()[0].name == "action"
    bad = CliRunner().invoke(app, ["export", str(tmp_path), "-o", str(tmp_path / "q.onnx")])
    assert bad.exit_code == 2 and "holds no manifest.json" in bad.stderr
    assert CliRunner().invoke(app, ["export", str(folder), "-o", str(tmp_path / "p.txt")]).exit_code == 2
    # a phrase whose training kept its start stores no policy: the line names the start to export instead
    kept = tmp_path / "kept"
    kept.mkdir()
    manifest = {**json.loads((folder / "manifest.json").read_text()), "kept": "start", "start": {"path": "models/x"}}
    (kept / "manifest.json").write_text(json.dumps(manifest))
    said = CliRunner().invoke(app, ["export", str(kept), "-o", str(tmp_path / "k.onnx")])
    assert said.exit_code == 2 and "kept its start policy" in said.stderr
    assert "pianobot export models/x -o" in said.stderr and len(said.stderr.strip().splitlines()) == 1


def test_a_finger_shared_policy_exports_with_the_vector_alone(tmp_path):
    from pianobot.agent.config import SACConfig
    from pianobot.agent.export import export_onnx
    from pianobot.env.piano import EnvConfig
    from pianobot.learn.config import DaggerConfig, TrainConfig
    from pianobot.learn.dagger import dagger_policy

    phrase = pianobot.Piece((pianobot.Note(0.0, 64, 0.5, 80, 3),), bpm=60)
    config = TrainConfig(
        learner="dagger",
        steps=70,
        eval_episodes=1,
        sac=SACConfig(hidden=16, actor="fingers"),
        dagger=DaggerConfig(round_steps=70, batch_size=16),
        env=EnvConfig(tactile=True),  # touch observed, but this actor does not read it
    )
    dagger_policy(phrase, config, tmp_path / "m")
    session = ort.InferenceSession(str(export_onnx(tmp_path / "m", tmp_path / "p.onnx")))
    assert [i.name for i in session.get_inputs()] == ["vector"]
    env = pianobot.PianoEnv(piece=phrase, config=config.env)
    policy = pianobot.load_policy(tmp_path / "m", env)
    observation, _ = env.reset(seed=1)
    for _ in range(10):
        vector, _ = policy.split(observation)
        action = session.run(None, {"vector": np.stack([vector] * 3)})[0]
        assert action.shape == (3, 13) and np.allclose(action[1], policy.act(observation), atol=1e-5)
        observation, *_ = env.step(action[0])
    env.close()


@pytest.mark.parametrize("which", ["twinkle phrase (touch)", "general policy (vector alone)"])
def test_the_model_pages_onnx_example_acts_as_pianobot_does(tmp_path, monkeypatch, which):
    """docs/models.md's onnxruntime block, run as written beside an exported policy: the inputs it
    names and the action it gives are pianobot's."""
    import re

    from pianobot.agent.export import export_onnx
    from pianobot.agent.general import PACKAGED

    piece = pianobot.load_piece(ROOT / "examples" / "midi" / "twinkle.mid")
    phrase = pianobot.split_phrases(piece)[0]
    folder = (
        next((ROOT / "models").glob(f"{phrase.hash}-*")) if "touch" in which else next(PACKAGED.glob("task-melody-*"))
    )
    export_onnx(folder, tmp_path / "policy.onnx")
    (block,) = [
        b
        for b in re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "models.md").read_text(), re.S)
        if "onnxruntime" in b
    ]
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(block, "docs/models.md", "exec"), namespace)
    env_config, _ = pianobot.policy_configs(folder)
    env = pianobot.PianoEnv(piece=phrase.piece(), config=env_config)
    policy = pianobot.load_policy(folder, env)
    vector, tactile = policy.split(env.reset(seed=2)[0])
    assert namespace["inputs"]["vector"] == ["batch", len(vector)]
    if "touch" in which:
        assert namespace["inputs"]["tactile"] == ["batch", *tactile.shape] == ["batch", 2, 3, 15, 20]
        assert len(vector) == 1358  # the figure the page gives
    else:
        assert "tactile" not in namespace["inputs"]
    observation, _ = env.reset(seed=2)
    for _ in range(15):
        action = namespace["act"](observation)
        assert action.dtype == np.float32 and np.allclose(action, policy.act(observation), atol=1e-5)
        observation, *_ = env.step(action)
    env.close()
