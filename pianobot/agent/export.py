"""A stored policy as an ONNX graph, for running it on a robot or in any ONNX runtime.

The graph is the deterministic policy: inputs ``vector`` (batch, V) float32, the observation
vector in the order docs/models.md gives, and, for a policy whose actor reads touch, ``tactile``
(batch, 2, fingers, rows, cols) uint8; output ``action`` (batch, A) in [-1, 1]. The policy's manifest goes
into the graph's metadata (``pianobot_manifest``), so the file says how it was trained and which
environment it expects.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import torch
from torch import nn

from pianobot.agent import store
from pianobot.agent.policy import load_policy, policy_configs
from pianobot.agent.sac import SAC
from pianobot.errors import PianobotError
from pianobot.files import check_writable, move_into_place, temporary_beside


class DeterministicPolicy(nn.Module):
    """Encoder and actor as one module: observation inputs -> the deterministic action."""

    def __init__(self, agent: SAC):
        super().__init__()
        self.actor = agent.actor
        self.encoder = agent.critic.encoder if agent.actor.reads_features else None

    def forward(self, vector: torch.Tensor, tactile: torch.Tensor | None = None) -> torch.Tensor:
        features = self.encoder(vector, tactile) if self.actor.reads_features else None
        return self.actor.deterministic(features, vector)


def export_onnx(folder: Path, path: Path) -> Path:
    """Write the policy stored in ``folder`` to ``path`` as ONNX (atomically)."""
    try:
        import onnx
    except ImportError:
        raise PianobotError("exporting to ONNX needs the onnx package: pip install 'pianobot[export]'") from None
    from pianobot.env.piano import PianoEnv
    from pianobot.music.tasks import TASKS

    path = check_writable(path)
    env_config, _ = policy_configs(folder)
    env = PianoEnv(task=TASKS[0], config=env_config)  # any episode: only the spaces matter
    try:
        agent = load_policy(folder, env)
        observation, _ = env.reset(seed=0)
    finally:
        env.close()
    vector, tactile = agent.split(observation)
    if not agent.actor.reads_features:
        tactile = None  # the actor reads the vector alone
    inputs = (torch.from_numpy(vector)[None],) + (() if tactile is None else (torch.from_numpy(tactile)[None],))
    names = ["vector"] + ([] if tactile is None else ["tactile"])
    tmp = temporary_beside(path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # torch's notice that the TorchScript-based exporter is the older one
            torch.onnx.export(
                DeterministicPolicy(agent).eval(),
                inputs,
                tmp,
                input_names=names,
                output_names=["action"],
                dynamic_axes={name: {0: "batch"} for name in [*names, "action"]},
                dynamo=False,
            )
        model = onnx.load(tmp)
        manifest = store.read_manifest(folder)
        onnx.helper.set_model_props(
            model, {"pianobot_manifest": json.dumps(manifest), "pianobot_inputs": ",".join(names)}
        )
        onnx.save(model, tmp)
        move_into_place(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
