"""Behaviour cloning of an agent's policy towards a teacher's actions (the learner of DAgger,
:mod:`pianobot.learn.dagger`). Not in the paper.

One gradient step moves the actor and the encoder together (in SAC the encoder learns from the
critic alone; an actor that does not read the encoder, ``SACConfig.actor`` 'fingers', moves
alone): the loss is the squared error of the deterministic action (tanh of the mean) to the
teacher's, averaged over action dimensions. A strike fails once the finger joints' speeds
stray about 0.02 from the teacher's (docs/benchmarks.md, "How precise must a policy be?"), so the
loss worth reaching is around 4e-4. The policy's spread (its log standard deviation) is pulled
towards :data:`FINE_TUNING_STD`, so that SAC fine-tuning from a cloned policy begins by exploring
with a noise a strike survives, not with the untrained head's.
"""

from __future__ import annotations

import math

import torch

from pianobot.agent.sac import SAC

FINE_TUNING_STD = 0.02
"""The standard deviation (before the tanh) a cloned policy leaves for SAC to explore with."""


class Imitation:
    """Adam over the actor of ``agent`` (and its encoder, when the actor reads it); :meth:`update`
    is one gradient step."""

    def __init__(self, agent: SAC, learning_rate: float):
        self.agent = agent
        parameters = list(agent.actor.parameters())
        if agent.actor.reads_features:
            parameters = list(agent.critic.encoder.parameters()) + parameters
        self.optimizer = torch.optim.Adam(parameters, lr=learning_rate)

    def set_learning_rate(self, learning_rate: float) -> None:
        for group in self.optimizer.param_groups:
            group["lr"] = learning_rate

    def update(self, batch: dict[str, torch.Tensor]) -> dict[str, float]:
        """One step on a batch whose ``expert`` rows are the teacher's actions (every row must have one)."""
        agent = self.agent
        features = agent.critic.encoder(batch["vector"], batch["tactile"]) if agent.actor.reads_features else None
        mean, log_std = agent.actor.heads(features, batch["vector"])
        cloning = (torch.tanh(mean) - batch["expert"]).pow(2).mean()
        low, high = agent.actor.log_std_bounds
        squashed = low + 0.5 * (high - low) * (torch.tanh(log_std) + 1)  # as the actor bounds it
        spread = (squashed - math.log(FINE_TUNING_STD)).pow(2).mean()
        loss = cloning + 1e-3 * spread
        self.optimizer.zero_grad(set_to_none=True)
        loss.backward()
        self.optimizer.step()
        agent.updates += 1
        return {"cloning_loss": float(cloning.detach())}

    def tensors(self) -> dict[str, torch.Tensor]:
        """Adam's state under flat names (``optim.imitation.*``), on the CPU, for checkpoints."""
        out = {}
        for index, state in self.optimizer.state_dict()["state"].items():
            for key, value in state.items():
                out[f"optim.imitation.{index}.{key}"] = value.reshape(-1) if value.dim() == 0 else value
        return {k: v.detach().cpu().contiguous().clone() for k, v in out.items()}

    def load_tensors(self, tensors: dict[str, torch.Tensor]) -> None:
        """Adam's state from :meth:`tensors` (other names are ignored)."""
        template = self.optimizer.state_dict()
        params = [p for group in self.optimizer.param_groups for p in group["params"]]
        state: dict[int, dict[str, torch.Tensor]] = {}
        prefix = "optim.imitation."
        for name, value in tensors.items():
            if name.startswith(prefix):
                index, field = name[len(prefix) :].split(".", 1)
                shape = () if field == "step" else params[int(index)].shape
                state.setdefault(int(index), {})[field] = value.reshape(shape).to(params[int(index)].device)
        template["state"] = state
        self.optimizer.load_state_dict(template)
