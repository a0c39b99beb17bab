"""The paper's rewards as pure functions of what was played and what the score asks for.

At each control step, over the L keys: ``played[k]`` is the normalised velocity (MIDI / 127)
of key k if it sounded during the step, else 0; ``target[k]`` is the score's velocity channel.
See docs/rewards.md for the equations.

- linear:       r = C - sum_k |played_k - target_k|                     (paper, eq. 1 with d = |.|)
- squared:      r = C - sum_k (played_k - target_k)^2
- wasserstein:  r = C - W_{d,sigma}(S, T)                                (paper, eqs. 3-4)

A closeness bonus (ours) rewards having each assigned fingertip near the key it is to play
next, the dense guidance RoboPianist also gives its agents; see docs/rewards.md.

The fingering gate (paper, section "Piano Playing Agent with Fingering Indicator") gives credit
for a target key only when the finger the score asks for is the one that pressed it, as told by
touch: a target key pressed by another finger counts as not played.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pianobot.config import check_ranges

REWARDS = ("linear", "squared", "wasserstein")


@dataclass(frozen=True)
class RewardConfig:
    """Which reward, and its constants."""

    kind: str = "linear"
    """'linear', 'squared' or 'wasserstein'."""
    constant: float = 1.0
    """The paper's Const: keeps the reward positive when one key is wrong."""
    sigma: float = 0.5
    """Wasserstein: cost of adding or removing one pressed key."""
    key_cost: float = 0.1
    """Wasserstein: cost per semitone of moving a pressed key onto a target key."""
    fingering_gate: bool = True
    """Credit a target key only when the score's finger pressed it (needs fingering in the score)."""
    closeness_weight: float = 0.5
    """Ours, not the paper's: a bonus of up to this much per step for having each assigned fingertip
    near the key it is to play next (0 turns it off). Without it SAC learnt to do nothing."""
    closeness_scale: float = 0.02
    """Distance (m) at which the closeness bonus has fallen to 1/e."""
    pedal_weight: float = 0.2
    """With the pedal an action (``EnvConfig.pedal_action``): this much per step for a foot that holds
    the pedal as the score's pedal says, down or up (RoboPianist rewards its sustain likewise)."""

    def __post_init__(self) -> None:
        if self.kind not in REWARDS:
            raise ValueError(f"reward must be one of {', '.join(REWARDS)}; got {self.kind!r}")
        check_ranges(
            self,
            constant=(0.0, 1e3),
            sigma=(0.0, 1e3),
            key_cost=(0.0, 1e3),
            closeness_weight=(0.0, 1e3),
            closeness_scale=(1e-4, 1.0),
            pedal_weight=(0.0, 1e3),
        )


def gate(played: np.ndarray, played_finger: np.ndarray, target: np.ndarray, target_finger: np.ndarray) -> np.ndarray:
    """Zero the played velocity of target keys pressed by a finger other than the score's.

    ``played_finger`` / ``target_finger`` hold finger numbers, 0 where unknown or unspecified;
    keys without a target finger are left alone.
    """
    wrong = (target > 0) & (target_finger > 0) & (played > 0) & (played_finger != target_finger)
    return np.where(wrong, 0.0, played)


def linear_distance(played: np.ndarray, target: np.ndarray) -> float:
    return float(np.abs(played - target).sum())


def squared_distance(played: np.ndarray, target: np.ndarray) -> float:
    return float(((played - target) ** 2).sum())


def wasserstein_distance(played: np.ndarray, target: np.ndarray, sigma: float, key_cost: float) -> float:
    """W_{d,sigma}(S, T) = min over X with |X| = |T| of sum_i d(X_i, T_i) + sigma |X symmetric-difference S|.

    S and T are the keys with non-zero played / target velocity; d(x, t) = key_cost * |x - t|
    (semitones) + |v_x - v_t|. Solved as an assignment problem: each played key is moved onto a
    target key (cost d) or removed (cost sigma); each target key left over is added (cost sigma).
    """
    s = np.flatnonzero(played > 0)
    t = np.flatnonzero(target > 0)
    if len(s) == 0 or len(t) == 0:
        return sigma * (len(s) + len(t))
    n = len(s) + len(t)
    cost = np.zeros((n, n))
    move = key_cost * np.abs(s[:, None] - t[None, :]) + np.abs(played[s][:, None] - target[t][None, :])
    cost[: len(s), : len(t)] = move
    cost[: len(s), len(t) :] = sigma  # remove a played key
    cost[len(s) :, : len(t)] = sigma  # add a target key
    from scipy.optimize import linear_sum_assignment  # only this reward needs scipy, slow to import

    rows, cols = linear_sum_assignment(cost)
    return float(cost[rows, cols].sum())


def closeness(distances: np.ndarray, scale: float) -> float:
    """Mean of exp(-(d / scale)^2) over the assigned fingertips' distances to their keys; 0 if none."""
    distances = np.asarray(distances, dtype=float)
    return float(np.exp(-((distances / scale) ** 2)).mean()) if distances.size else 0.0


def reward_terms(
    config: RewardConfig,
    played: np.ndarray,
    played_finger: np.ndarray,
    target: np.ndarray,
    target_finger: np.ndarray,
    fingertip_distances: np.ndarray | None = None,
) -> dict[str, float]:
    """The named terms whose sum is the reward of one step.

    ``fingertip_distances``: for each key the score asks to play now or next (within the
    lookahead), the distance from its assigned fingertip to the key's strike point."""
    if config.fingering_gate:
        played = gate(played, played_finger, target, target_finger)
    if config.kind == "linear":
        penalty = linear_distance(played, target)
    elif config.kind == "squared":
        penalty = squared_distance(played, target)
    else:
        penalty = wasserstein_distance(played, target, config.sigma, config.key_cost)
    terms = {"constant": config.constant, config.kind: -penalty}
    if config.closeness_weight and fingertip_distances is not None:
        terms["closeness"] = config.closeness_weight * closeness(fingertip_distances, config.closeness_scale)
    return terms
