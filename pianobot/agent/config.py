"""The agent's hyperparameters, apart from the networks' code so that reading them costs no torch import."""

from __future__ import annotations

from dataclasses import dataclass

DEVICES = ("auto", "cpu", "cuda")
"""Where the learner can run (``TrainConfig.device``): 'auto' is cuda when torch sees a GPU, else cpu."""
ACTORS = ("mlp", "fingers")
"""The actor's networks (``SACConfig.actor``)."""


@dataclass(frozen=True)
class SACConfig:
    """Every hyperparameter of the agent, with its default. The single source of defaults."""

    discount: float = 0.9
    """RoboPianist found 0.8-0.9 better than 0.99 for piano playing (the paper does not say)."""
    batch_size: int = 256
    learning_rate: float = 3e-4
    """Adam, for actor, critic and temperature. The paper's 1e-3 made task-family evaluations
    swing by 0.3 of F1 from one to the next (docs/training.md)."""
    initial_alpha: float = 0.02
    """Initial entropy temperature (paper)."""
    target_entropy_scale: float = 2.5
    """Target entropy = -scale * action dimensions. A Gaussian's entropy is 1.42 + ln(sigma) per
    dimension, so 2.5 lets the policy explore with a noise of about 0.02 per action on average:
    more than that and a strike fails (docs/benchmarks.md, "How precise must a policy be?").
    The usual 1.0 (sigma near 0.09) failed most of the policy's own training episodes."""
    tau: float = 0.005
    """Polyak factor of the target critic."""
    hidden: int = 256
    """Width of the MLP layers."""
    actor: str = "mlp"
    """The actor's networks. 'mlp' (the paper's): a two-layer MLP over the encoder's features (vector
    and touch). 'fingers': one three-layer MLP shared by the fingers, each finger reading its own
    joints, joint speeds and finger target, which finger it is, and the whole observation vector,
    and a three-layer MLP for the wrist; it reads the observation vector itself, not the encoder
    (so neither touch nor the score window), and needs the finger targets. What one finger learns
    to do for a key serves the others: imitating the scripted pianist, it plays melodies it never
    saw far better than the 'mlp' actor (docs/training.md, "The finger-shared actor")."""
    score_input: bool = False
    """Feed the score window (L keys x 5 channels x lookahead steps, the paper's input) to the
    networks. Off by default: the finger targets in the observation say, for each finger, where
    its next key is, how soon and how loud, which is what the window's key-indexed one-hots say
    in a form that does not depend on the key; with the window a policy learns the keys it has
    seen one by one (docs/training.md)."""
    score_features: int = 64
    """Width of the first layer over the (large, sparse) score window, when it is read."""
    tactile_channels: int = 8
    """Channels of the tactile convolutions."""
    tactile_features: int = 32
    """Features per finger from the tactile encoder."""
    buffer_size: int = 100_000
    """Replay buffer capacity (transitions)."""
    update_ratio: float = 1.0
    """Gradient updates per environment step once learning starts."""
    exploration_steps: int = 15_000
    """Environment steps of exploration before learning starts (paper: 15000)."""
    demo_weight: float = 1.0
    """Behaviour cloning towards a teacher's actions in the batch (the scripted pianist labels
    every step when exploring with it, as in DAgger), as in TD3+BC: the actor's loss is
    ``demo_q_weight * SAC loss / mean |Q| + demo_weight * squared error to the teacher's
    action``. 0 gives plain SAC. Not in the paper."""
    demo_q_weight: float = 2.5
    """TD3+BC's alpha: how much the critic counts against the demonstrations."""
    log_std_bounds: tuple[float, float] = (-5.0, 2.0)

    def __post_init__(self) -> None:
        for name, most in (
            ("batch_size", 1 << 16),
            ("hidden", 4096),
            ("score_features", 4096),
            ("tactile_channels", 256),
            ("tactile_features", 1024),
            ("buffer_size", 10_000_000),
        ):
            value = getattr(self, name)
            if not 1 <= value <= most:
                raise ValueError(f"{name} {value} must be between 1 and {most}")
        if not (0 <= self.discount <= 1 and 0 < self.tau <= 1 and self.learning_rate > 0 and self.update_ratio > 0):
            raise ValueError("discount must lie in [0, 1], tau in (0, 1], learning_rate and update_ratio above 0")
        if self.exploration_steps < 0 or self.initial_alpha <= 0 or self.demo_weight < 0 or self.demo_q_weight < 0:
            raise ValueError(
                "exploration_steps, demo_weight and demo_q_weight cannot be negative, initial_alpha must be above 0"
            )
        if self.actor not in ACTORS:
            raise ValueError(f"actor {self.actor!r} must be one of {', '.join(ACTORS)}")
        if not self.log_std_bounds[0] < self.log_std_bounds[1]:
            raise ValueError(f"log_std_bounds {self.log_std_bounds} must rise")
