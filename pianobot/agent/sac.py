"""Soft Actor-Critic (paper, section "Soft Actor-Critic"), written for a CPU; it runs on a GPU too
(``device``, :func:`resolve_device`), and its tensors are always handed out and stored on the CPU.

Networks (paper, "Architecture"): a tactile encoder of three convolution layers shared across
fingers, a three-layer MLP for the vector inputs (finger targets, wrist, joints; the score
window only with ``score_input``), their features concatenated and fed to two-layer heads; ReLU
throughout. ``SACConfig.actor`` 'fingers' gives the actor networks of its own instead, over the
observation vector: one MLP shared by the fingers and one for the wrist (:mod:`pianobot.agent.actors`).
The critic's two Q heads are one batched network (weights stacked on a leading axis, one
``baddbmm`` per layer), so both critics cost one forward and one optimiser step. The encoder
belongs to the critic and the 'mlp' actor reads its features detached (as in DrQ): one encoder
pass per update serves both.

Everything tunable is in :class:`~pianobot.agent.config.SACConfig`; docs/training.md says where our defaults differ
from the paper's and why.
"""

from __future__ import annotations

import math

import numpy as np
import torch
from torch import nn
from torch.nn import functional as F

from pianobot.agent.actors import Actor, FingerActor, FingerLayout, GaussianActor
from pianobot.agent.config import DEVICES, SACConfig
from pianobot.errors import SettingError, quote

# -- observation layout -----------------------------------------------------------------------
VECTOR_KEYS = ("score", "wrist", "joints", "joint_velocities", "targets", "keys", "key_velocities", "pedal")
"""What the flat vector holds, in order (each where the environment observes it)."""


def _keys(score: bool) -> tuple[str, ...]:
    return VECTOR_KEYS if score else VECTOR_KEYS[1:]


def vector_size(observation_space, score: bool = True) -> int:
    """Length of the flat vector (with or without the score window, which comes first)."""
    return sum(int(np.prod(observation_space[k].shape)) for k in _keys(score) if k in observation_space.spaces)


def score_size(observation_space, score: bool = True) -> int:
    """Length of the score window at the start of the flat vector (0 without it)."""
    return int(np.prod(observation_space["score"].shape)) if score else 0


def split_observation(observation: dict, score: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """A dict observation as (flat float32 vector, uint8 tactile images or None); ``score``: with
    the score window (an agent that does not read it need not store it)."""
    vector = np.concatenate([np.asarray(observation[k], np.float32).ravel() for k in _keys(score) if k in observation])
    return vector, observation.get("tactile")


def split_observations(observations: dict, score: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`split_observation` for a batch: a vector environment's observations, one row per environment."""
    count = len(observations["wrist"])
    vectors = np.concatenate(
        [np.asarray(observations[k], np.float32).reshape(count, -1) for k in _keys(score) if k in observations], axis=1
    )
    return vectors, observations.get("tactile")


# -- networks ---------------------------------------------------------------------------------
class Encoder(nn.Module):
    """Observation -> features: a 3-layer MLP on the vector, 3 conv layers on each fingertip's images."""

    def __init__(self, vector_dim: int, score_dim: int, tactile_shape: tuple[int, ...] | None, config: SACConfig):
        super().__init__()
        h = config.hidden
        self.score_dim = score_dim
        # the score window is large and sparse (L keys x 5 x steps): a narrow first layer for it
        # keeps the MLP's cost down; the joint and wrist values join it in the second layer.
        # Without score input the vector's first score_dim values are skipped.
        self.score = (
            nn.Sequential(nn.Linear(score_dim, config.score_features), nn.ReLU()) if config.score_input else None
        )
        score_width = config.score_features if config.score_input else 0
        self.vector = nn.Sequential(
            nn.Linear(score_width + vector_dim - score_dim, h), nn.ReLU(), nn.Linear(h, h), nn.ReLU()
        )
        self.out_dim = h
        self.tactile = None
        if tactile_shape is not None:
            history, fingers, rows, cols = tactile_shape
            c = config.tactile_channels
            conv = nn.Sequential(
                nn.Conv2d(history, c, 3, stride=2),
                nn.ReLU(),
                nn.Conv2d(c, c, 3),
                nn.ReLU(),
                nn.Conv2d(c, c, 3),
                nn.ReLU(),
                nn.Flatten(),
            )
            with torch.no_grad():
                flat = conv(torch.zeros(1, history, rows, cols)).shape[1]
            self.tactile = nn.Sequential(conv, nn.Linear(flat, config.tactile_features), nn.ReLU())
            self.out_dim += fingers * config.tactile_features

    def forward(self, vector: torch.Tensor, tactile: torch.Tensor | None) -> torch.Tensor:
        rest = vector[:, self.score_dim :]
        features = self.vector(
            rest if self.score is None else torch.cat([self.score(vector[:, : self.score_dim]), rest], dim=1)
        )
        if self.tactile is None:
            return features
        batch, history, fingers, rows, cols = tactile.shape
        # the same convolutions for every finger: fingers go into the batch dimension
        images = tactile.float().div_(255.0).transpose(1, 2).reshape(batch * fingers, history, rows, cols)
        touch = self.tactile(images).reshape(batch, -1)
        return torch.cat([features, touch], dim=1)


class EnsembleLinear(nn.Module):
    """``members`` independent linear layers evaluated in one batched matrix product."""

    def __init__(self, members: int, in_features: int, out_features: int):
        super().__init__()
        bound = 1.0 / math.sqrt(in_features)
        self.weight = nn.Parameter(torch.empty(members, in_features, out_features).uniform_(-bound, bound))
        self.bias = nn.Parameter(torch.empty(members, 1, out_features).uniform_(-bound, bound))

    def forward(self, x: torch.Tensor) -> torch.Tensor:  # (members, batch, in) -> (members, batch, out)
        return torch.baddbmm(self.bias, x, self.weight)


class Critic(nn.Module):
    """The encoder and two Q heads (2-layer MLPs over features and action) as one ensemble."""

    def __init__(self, vector_dim: int, score_dim: int, tactile_shape, action_dim: int, config: SACConfig):
        super().__init__()
        self.encoder = Encoder(vector_dim, score_dim, tactile_shape, config)
        h = config.hidden
        self.layers = nn.ModuleList(
            [EnsembleLinear(2, self.encoder.out_dim + action_dim, h), EnsembleLinear(2, h, h), EnsembleLinear(2, h, 1)]
        )

    def q(self, features: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        """Both critics' values, shape (2, batch)."""
        x = torch.cat([features, action], dim=1).unsqueeze(0).expand(2, -1, -1)
        x = F.relu(self.layers[0](x))
        x = F.relu(self.layers[1](x))
        return self.layers[2](x).squeeze(-1)


def _load_checked(module: nn.Module, state: dict[str, torch.Tensor], prefix: str) -> None:
    """``module.load_state_dict(state)``, after checking every tensor's name, shape, type and
    values, so that a file that does not fit says which tensor and why (ValueError)."""
    expected = module.state_dict()
    for name in sorted(set(expected) | set(state)):
        if name not in state:
            raise ValueError(f"tensor {prefix}{name} is missing")
        if name not in expected:
            raise ValueError(f"tensor {prefix}{name} is not part of this agent")
        tensor, own = state[name], expected[name]
        if tuple(tensor.shape) != tuple(own.shape):
            raise ValueError(
                f"tensor {prefix}{name} has shape {tuple(tensor.shape)}, this agent's is {tuple(own.shape)}"
            )
        if tensor.dtype != own.dtype:
            raise ValueError(f"tensor {prefix}{name} is {tensor.dtype}, this agent's is {own.dtype}")
        if not bool(torch.isfinite(tensor).all()):
            raise ValueError(f"tensor {prefix}{name} holds NaN or infinite values")
    module.load_state_dict(state)


def resolve_device(name: str) -> torch.device:
    """The device the learner runs on: 'cpu', 'cuda', or 'auto' (cuda when torch sees a GPU, else
    cpu). Asking for cuda where torch sees none is a one-line :class:`PianobotError`."""
    if name not in DEVICES:
        raise SettingError(f"train.device {quote(name)}: choose one of {', '.join(DEVICES)}", "train.device")
    if name == "auto":
        name = "cuda" if torch.cuda.is_available() else "cpu"
    if name == "cuda" and not torch.cuda.is_available():
        raise SettingError(
            f"train.device cuda: torch {torch.__version__} sees no CUDA GPU on this machine: use train.device cpu, "
            "or auto (cuda where there is one)",
            "train.device",
        )
    return torch.device(name)


# -- the agent --------------------------------------------------------------------------------
class SAC:
    """Actor, twin critic with targets, learned temperature; :meth:`update` is one gradient step."""

    def __init__(
        self,
        vector_dim: int,
        score_dim: int,
        tactile_shape,
        action_dim: int,
        config: SACConfig = SACConfig(),
        device: str | torch.device = "cpu",
        layout: FingerLayout | None = None,
        training: bool = True,
    ):
        """``layout``: where the fingers' values lie in the vector (:func:`~pianobot.agent.actors.finger_layout`), which
        the 'fingers' actor needs. ``training`` False builds only what acting needs (the actor
        and the encoder it reads): no target critic, no optimisers, so that a policy loaded to
        play costs neither their memory nor the import of torch's optimiser and compiler modules."""
        self.config = config
        self.device = torch.device(device)
        self.training = training
        acting_alone = not training and config.actor == "fingers"  # (an actor that reads no encoder: none is built)
        self.critic = (
            None if acting_alone else Critic(vector_dim, score_dim, tactile_shape, action_dim, config).to(self.device)
        )
        if config.actor == "fingers":
            if layout is None:
                raise ValueError(
                    "the 'fingers' actor reads each finger's target: it needs the finger target observations"
                )
            self.actor: GaussianActor = FingerActor(vector_dim, score_dim, action_dim, layout, config).to(self.device)
        else:
            self.actor = Actor(self.critic.encoder.out_dim, action_dim, config).to(self.device)
        self.log_alpha = torch.tensor(math.log(config.initial_alpha), device=self.device, requires_grad=True)
        self.target_entropy = -config.target_entropy_scale * action_dim
        self.updates = 0
        if not training:
            if self.critic is not None:
                self.critic.requires_grad_(False)
            self.actor.requires_grad_(False)
            return
        self.target = Critic(vector_dim, score_dim, tactile_shape, action_dim, config).to(self.device)
        self.target.load_state_dict(self.critic.state_dict())
        self.target.requires_grad_(False)
        lr = config.learning_rate
        self.critic_optimizer = torch.optim.Adam(self.critic.parameters(), lr=lr)
        self.actor_optimizer = torch.optim.Adam(self.actor.parameters(), lr=lr)
        self.alpha_optimizer = torch.optim.Adam([self.log_alpha], lr=lr)
        self._critic_params = list(self.critic.parameters())
        self._target_params = list(self.target.parameters())

    @property
    def alpha(self) -> torch.Tensor:
        return self.log_alpha.exp()

    def split(self, observation: dict) -> tuple[np.ndarray, np.ndarray | None]:
        """:func:`split_observation` as this agent reads observations (with or without the score window)."""
        return split_observation(observation, self.config.score_input)

    def split_batch(self, observations: dict) -> tuple[np.ndarray, np.ndarray | None]:
        """:meth:`split` for a vector environment's observations (:func:`split_observations`)."""
        return split_observations(observations, self.config.score_input)

    # -- acting: the controller interface (reset, act) and training's noisy samples -------------
    def reset(self) -> None:
        """Start of an episode: a policy remembers nothing between steps, so nothing to do."""

    @torch.no_grad()
    def act(self, observation: dict) -> np.ndarray:
        """The deterministic action for an observation (evaluation and performance)."""
        vector, tactile = self.split(observation)
        return self.act_batch(vector[None], None if tactile is None else tactile[None])[0]

    @torch.no_grad()
    def act_batch(self, vectors: np.ndarray, tactiles: np.ndarray | None) -> np.ndarray:
        """Deterministic actions for a batch of :meth:`split` inputs, one row per environment."""
        return self.actor.deterministic(*self._actor_inputs(vectors, tactiles)).cpu().numpy()

    def sample(self, vector: np.ndarray, tactile: np.ndarray | None) -> np.ndarray:
        """A noisy action from :meth:`split` inputs (training's behaviour policy)."""
        return self.sample_batch(vector[None], None if tactile is None else tactile[None])[0]

    @torch.no_grad()
    def sample_batch(self, vectors: np.ndarray, tactiles: np.ndarray | None) -> np.ndarray:
        """Noisy actions for a batch of :meth:`split` inputs, one row per environment."""
        action, _, _ = self.actor(*self._actor_inputs(vectors, tactiles))
        return action.cpu().numpy()

    def _actor_inputs(
        self, vectors: np.ndarray, tactiles: np.ndarray | None
    ) -> tuple[torch.Tensor | None, torch.Tensor]:
        """(the encoder's features, or None for an actor that does not read them; the vector) as tensors."""
        v = torch.from_numpy(np.asarray(vectors, np.float32)).to(self.device)
        if not self.actor.reads_features:
            return None, v
        t = None if tactiles is None else torch.from_numpy(np.asarray(tactiles)).to(self.device)
        return self.critic.encoder(v, t), v

    def update(self, batch: dict[str, torch.Tensor]) -> dict[str, float]:
        """One gradient step on critic, actor and temperature from a replay batch."""
        alpha = self.alpha.detach()
        now = self.critic.encoder(batch["vector"], batch["tactile"])
        with torch.no_grad():
            after = (
                self.critic.encoder(batch["next_vector"], batch["next_tactile"]) if self.actor.reads_features else None
            )
            next_action, next_log_prob, _ = self.actor(after, batch["next_vector"])
            target_features = self.target.encoder(batch["next_vector"], batch["next_tactile"])
            next_q = self.target.q(target_features, next_action).min(dim=0).values - alpha * next_log_prob
            target_q = batch["reward"] + self.config.discount * (1.0 - batch["terminated"]) * next_q

        q = self.critic.q(now, batch["action"])
        critic_loss = 0.5 * (q - target_q.unsqueeze(0)).pow(2).sum(0).mean()
        self.critic_optimizer.zero_grad(set_to_none=True)
        critic_loss.backward()
        self.critic_optimizer.step()

        features = now.detach()
        action, log_prob, mean_action = self.actor(features if self.actor.reads_features else None, batch["vector"])
        self.critic.layers.requires_grad_(False)  # the actor's loss needs no gradient for the critic
        actor_q = self.critic.q(features, action).min(dim=0).values
        actor_loss = (alpha * log_prob - actor_q).mean()
        demo = batch.get("demo")
        if self.config.demo_weight > 0 and demo is not None and bool(demo.any()):
            # TD3+BC: the critic's term normalised by the scale of Q, plus cloning the demonstrations
            cloning = ((mean_action - batch["expert"]).pow(2).sum(-1) * demo).sum() / demo.sum()
            scale = self.config.demo_q_weight / actor_q.abs().mean().detach().clamp(min=1e-3)
            actor_loss = scale * actor_loss + self.config.demo_weight * cloning
        self.actor_optimizer.zero_grad(set_to_none=True)
        actor_loss.backward()
        self.actor_optimizer.step()
        self.critic.layers.requires_grad_(True)

        alpha_loss = -(self.log_alpha * (log_prob.detach() + self.target_entropy)).mean()
        self.alpha_optimizer.zero_grad(set_to_none=True)
        alpha_loss.backward()
        self.alpha_optimizer.step()

        with torch.no_grad():
            for target, online in zip(self._target_params, self._critic_params):
                target.lerp_(online, self.config.tau)
        self.updates += 1
        return {
            "critic_loss": float(critic_loss.detach()),
            "actor_loss": float(actor_loss.detach()),
            "alpha": float(alpha),
            "entropy": float(-log_prob.detach().mean()),
            "q": float(q.detach().mean()),
        }

    # -- (de)serialisation as flat tensors, for safetensors ----------------------------------
    def tensors(self, with_training_state: bool = True) -> dict[str, torch.Tensor]:
        """Every tensor of the agent under a flat name. Without training state: the actor and encoder only."""
        out = {f"actor.{k}": v for k, v in self.actor.state_dict().items()}
        if self.critic is not None:
            out.update({f"encoder.{k}": v for k, v in self.critic.encoder.state_dict().items()})
        if with_training_state:
            out.update({f"critic.{k}": v for k, v in self.critic.state_dict().items() if not k.startswith("encoder.")})
            out.update({f"target.{k}": v for k, v in self.target.state_dict().items()})
            out["log_alpha"] = self.log_alpha.detach().reshape(1)
            for name, optimizer in self._optimizers().items():
                for index, state in optimizer.state_dict()["state"].items():
                    for key, value in state.items():
                        out[f"optim.{name}.{index}.{key}"] = value.reshape(-1) if value.dim() == 0 else value
        return {k: v.detach().cpu().contiguous().clone() for k, v in out.items()}

    def load_tensors(self, tensors: dict[str, torch.Tensor], with_training_state: bool = True) -> None:
        """Load :meth:`tensors`' output; raises ValueError naming the first tensor that does not fit."""
        # files of manifest format 1 also held the tactile convolutions under encoder.conv.*,
        # a second name for encoder.tactile.0.*
        tensors = {k: v for k, v in tensors.items() if "encoder.conv." not in k}

        def section(prefix: str) -> dict[str, torch.Tensor]:
            return {k[len(prefix) :]: v for k, v in tensors.items() if k.startswith(prefix)}

        _load_checked(self.actor, section("actor."), "actor.")
        if self.critic is None:  # (built to act, with an actor that reads no encoder)
            return
        _load_checked(self.critic.encoder, section("encoder."), "encoder.")
        if not with_training_state:
            return
        if not self.training:
            raise ValueError("an agent built to act (training=False) holds no training state to load")
        critic = section("critic.")
        critic.update({f"encoder.{k}": v for k, v in section("encoder.").items()})
        _load_checked(self.critic, critic, "critic.")
        _load_checked(self.target, section("target."), "target.")
        with torch.no_grad():
            self.log_alpha.copy_(tensors["log_alpha"][0])
        for name, optimizer in self._optimizers().items():
            template = optimizer.state_dict()
            params = [p for group in optimizer.param_groups for p in group["params"]]
            state: dict[int, dict[str, torch.Tensor]] = {}
            for key, value in section(f"optim.{name}.").items():
                index, field = key.split(".", 1)
                shape = () if field == "step" else params[int(index)].shape  # 0-d tensors were stored as (1,)
                state.setdefault(int(index), {})[field] = value.reshape(shape)
            template["state"] = state
            optimizer.load_state_dict(template)

    def critic_tensors(self) -> dict[str, torch.Tensor]:
        """What fine-tuning needs beyond the policy (:meth:`tensors` without training state): the
        twin Q heads (``critic.layers.*``; their encoder is the policy's ``encoder.*``) and the
        temperature (``log_alpha``), on the CPU. Stored beside a policy as ``critic.safetensors``."""
        out = {f"critic.{k}": v for k, v in self.critic.state_dict().items() if not k.startswith("encoder.")}
        out["log_alpha"] = self.log_alpha.detach().reshape(1)
        return {k: v.detach().cpu().contiguous().clone() for k, v in out.items()}

    def load_start(self, policy: dict[str, torch.Tensor], critic: dict[str, torch.Tensor] | None) -> None:
        """Begin training from a stored policy (fine-tuning): actor and encoder from ``policy``;
        the Q heads and the temperature from ``critic`` (:meth:`critic_tensors`) when given, else
        as initialised; the target critic a copy of the critic. Adam's moments start fresh. Raises
        ValueError naming the first tensor that does not fit."""
        self.load_tensors(policy, with_training_state=False)
        if critic is not None:
            heads = {k[len("critic.") :]: v for k, v in critic.items() if k.startswith("critic.")}
            heads.update({f"encoder.{k}": v for k, v in self.critic.encoder.state_dict().items()})
            _load_checked(self.critic, heads, "critic.")
            if "log_alpha" not in critic or critic["log_alpha"].numel() != 1:
                raise ValueError("tensor log_alpha is missing")
            if not bool(torch.isfinite(critic["log_alpha"]).all()):
                raise ValueError("tensor log_alpha holds NaN or infinite values")
            with torch.no_grad():
                self.log_alpha.copy_(critic["log_alpha"].reshape(()))
        self.target.load_state_dict(self.critic.state_dict())

    def _optimizers(self) -> dict[str, torch.optim.Optimizer]:
        return {"critic": self.critic_optimizer, "actor": self.actor_optimizer, "alpha": self.alpha_optimizer}
