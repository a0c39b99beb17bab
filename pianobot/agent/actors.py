"""The policies SAC learns (:mod:`pianobot.agent.sac`): a tanh-squashed Gaussian over the actions.

:class:`Actor` is the paper's, a two-layer MLP over the encoder's features (touch, the vector
inputs). :class:`FingerActor` (``SACConfig.actor`` 'fingers') reads the observation vector only:
one MLP shared by the fingers gives each finger's actions, one MLP the wrist's; fingers with
different joint counts are padded to the most (:class:`FingerLayout`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch
from torch import nn
from torch.nn import functional as F

from pianobot.agent.config import SACConfig

NO_FOOT = (
    " (the finger-shared actor has no foot: a policy that works the pedal, env.pedal_action, takes the 'mlp' actor)"
)


class GaussianActor(nn.Module):
    """A tanh-squashed Gaussian policy; a subclass's :meth:`heads` gives the mean and (unbounded)
    log standard deviation of each action."""

    reads_features = True
    """Whether :meth:`heads` reads the encoder's features (else only the observation vector)."""

    def __init__(self, config: SACConfig):
        super().__init__()
        self.log_std_bounds = config.log_std_bounds

    def heads(self, features: torch.Tensor | None, vector: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        raise NotImplementedError

    def forward(
        self, features: torch.Tensor | None, vector: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """(sampled action, its log-probability, the deterministic action: tanh of the mean)."""
        mean, log_std = self.heads(features, vector)
        low, high = self.log_std_bounds
        log_std = low + 0.5 * (high - low) * (torch.tanh(log_std) + 1)
        std = log_std.exp()
        noise = torch.randn_like(mean)
        raw = mean + std * noise
        action = torch.tanh(raw)
        # log-probability of the squashed sample (change of variables, numerically stable form)
        log_prob = (-0.5 * noise.pow(2) - log_std - 0.5 * math.log(2 * math.pi)).sum(-1)
        log_prob = log_prob - (2 * (math.log(2) - raw - F.softplus(-2 * raw))).sum(-1)
        return action, log_prob, torch.tanh(mean)

    def deterministic(self, features: torch.Tensor | None, vector: torch.Tensor) -> torch.Tensor:
        """The policy's action without noise: tanh of the mean."""
        return torch.tanh(self.heads(features, vector)[0])


class Actor(GaussianActor):
    """The 'mlp' actor (the paper's): a two-layer MLP over the encoder's features."""

    def __init__(self, feature_dim: int, action_dim: int, config: SACConfig):
        super().__init__(config)
        h = config.hidden
        self.net = nn.Sequential(
            nn.Linear(feature_dim, h), nn.ReLU(), nn.Linear(h, h), nn.ReLU(), nn.Linear(h, 2 * action_dim)
        )

    def heads(self, features: torch.Tensor | None, vector: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        return self.net(features).chunk(2, dim=-1)


def _mlp(inputs: int, outputs: int, hidden: int, layers: int = 3) -> nn.Sequential:
    modules: list[nn.Module] = []
    for _ in range(layers):
        modules += [nn.Linear(inputs, hidden), nn.ReLU()]
        inputs = hidden
    return nn.Sequential(*modules, nn.Linear(inputs, outputs))


@dataclass(frozen=True)
class FingerLayout:
    """Where each finger's values lie in the observation vector (after the score window): the
    wrist (2 values), then ``fingers * joints`` joint angles, as many joint speeds, and
    ``fingers * target_width`` finger targets, finger by finger (:class:`~pianobot.env.piano.PianoEnv`)."""

    fingers: int
    joints: int
    """Joints per finger (observed, actuated or not); the most any finger has, where they differ."""
    target_width: int
    counts: tuple[tuple[int, ...], tuple[int, ...]] | None = None
    """Where fingers differ: each finger's joints, and its actions (None: every finger alike)."""


def finger_layout(
    observation_space, counts: tuple[tuple[int, ...], tuple[int, ...]] | None = None
) -> FingerLayout | None:
    """The :class:`FingerLayout` of an environment's observations; None without finger targets.
    ``counts``: each finger's joints and actions (:func:`pianobot.env.piano.finger_counts`), for a
    hand whose fingers differ."""
    if "targets" not in observation_space.spaces:
        return None
    fingers, width = observation_space["targets"].shape
    if counts is not None and len(set(counts[0])) == len(set(counts[1])) == 1:
        counts = None  # (every finger alike: the one layout)
    if counts is not None:
        return FingerLayout(fingers, max(counts[0]), width, counts)
    return FingerLayout(fingers, observation_space["joints"].shape[0] // fingers, width)


class FingerActor(GaussianActor):
    """The 'fingers' actor: one MLP shared by the fingers gives each finger's actions from its own
    joints, joint speeds and target, its one-hot index and the whole observation vector; an MLP
    over the vector gives the wrist's. It reads the vector itself, after the score window (no
    touch, no score window). Actions are finger by finger, then the wrist, as the environment's."""

    reads_features = False

    def __init__(self, vector_dim: int, score_dim: int, action_dim: int, layout: FingerLayout, config: SACConfig):
        super().__init__(config)
        self.layout, self.score_dim = layout, score_dim
        if layout.counts is None:
            self.per_finger = (action_dim - 1) // layout.fingers
            if self.per_finger * layout.fingers + 1 != action_dim:
                raise ValueError(
                    f"{action_dim} actions are not {layout.fingers} fingers' alike plus the wrist{NO_FOOT}"
                )
        else:  # fingers that differ: each one's joints padded to the most (zeros), its actions the first of the most
            joints, moved = layout.counts
            self.per_finger = max(moved)
            if sum(moved) + 1 != action_dim:
                raise ValueError(f"{action_dim} actions are not the fingers' {sum(moved)} plus the wrist{NO_FOOT}")
            total = sum(joints)
            pad = [
                [sum(joints[:f]) + j if j < n else total for j in range(layout.joints)] for f, n in enumerate(joints)
            ]
            self.register_buffer("padded", torch.tensor(pad), persistent=False)
            kept = [f * self.per_finger + a for f, n in enumerate(moved) for a in range(n)]
            self.register_buffer("kept", torch.tensor(kept), persistent=False)
        context = vector_dim - score_dim
        own = 2 + 2 * layout.joints + layout.target_width + layout.fingers
        self.finger = _mlp(own + context, 2 * self.per_finger, config.hidden)
        self.wrist = _mlp(context, 2, config.hidden)
        self.register_buffer("which", torch.eye(layout.fingers), persistent=False)

    def heads(self, features: torch.Tensor | None, vector: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        v = vector[:, self.score_dim :]
        batch = v.shape[0]
        fingers, joints, width = self.layout.fingers, self.layout.joints, self.layout.target_width
        total = fingers * joints if self.layout.counts is None else sum(self.layout.counts[0])
        angles = 2  # after the wrist's position and speed: angles, speeds, targets, finger by finger
        speeds = angles + total
        targets = speeds + total
        own = [
            v[:, None, :2].expand(batch, fingers, 2),
            self._by_finger(v[:, angles:speeds]),
            self._by_finger(v[:, speeds:targets]),
            v[:, targets : targets + fingers * width].reshape(batch, fingers, width),
            self.which.expand(batch, fingers, fingers),
            v[:, None, :].expand(batch, fingers, v.shape[1]),
        ]
        out = self.finger(torch.cat(own, dim=-1))  # (batch, fingers, 2 * per_finger)
        finger_mean, finger_log_std = (half.reshape(batch, -1) for half in out.chunk(2, dim=-1))
        if self.layout.counts is not None:  # (each finger's own actions)
            finger_mean, finger_log_std = finger_mean[:, self.kept], finger_log_std[:, self.kept]
        wrist_mean, wrist_log_std = self.wrist(v).chunk(2, dim=-1)
        return torch.cat([finger_mean, wrist_mean], dim=1), torch.cat([finger_log_std, wrist_log_std], dim=1)

    def _by_finger(self, values: torch.Tensor) -> torch.Tensor:
        """(batch, fingers, joints): every finger's joints (padded with zeros where fingers differ)."""
        if self.layout.counts is None:
            return values.reshape(values.shape[0], self.layout.fingers, self.layout.joints)
        padded = torch.cat([values, values.new_zeros(values.shape[0], 1)], dim=1)
        return padded[:, self.padded]
