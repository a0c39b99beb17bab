"""A replay buffer of preallocated NumPy arrays; tactile images stay uint8 until a batch is drawn."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from pianobot.errors import PianobotError


class ReplayBuffer:
    """Transitions (o, a, r, terminated, o') in ring-buffer arrays."""

    def __init__(self, capacity: int, vector_dim: int, tactile_shape: tuple[int, ...] | None, action_dim: int):
        self.capacity = capacity
        self.arrays = {
            "vector": np.zeros((capacity, vector_dim), np.float32),
            "next_vector": np.zeros((capacity, vector_dim), np.float32),
            "action": np.zeros((capacity, action_dim), np.float32),
            "reward": np.zeros(capacity, np.float32),
            "terminated": np.zeros(capacity, np.float32),
            "demo": np.zeros(capacity, np.float32),
            "expert": np.zeros((capacity, action_dim), np.float32),
        }
        if tactile_shape is not None:
            self.arrays["tactile"] = np.zeros((capacity, *tactile_shape), np.uint8)
            self.arrays["next_tactile"] = np.zeros((capacity, *tactile_shape), np.uint8)
        self.size = 0
        self.cursor = 0

    def add(self, vector, tactile, action, reward, terminated, next_vector, next_tactile, expert=None) -> None:
        """One transition; ``expert``: what a teacher (the scripted pianist) would have done here."""
        i = self.cursor
        a = self.arrays
        a["vector"][i], a["next_vector"][i], a["action"][i] = vector, next_vector, action
        a["reward"][i], a["terminated"][i] = reward, float(terminated)
        a["demo"][i] = float(expert is not None)
        a["expert"][i] = 0.0 if expert is None else expert
        if "tactile" in a:
            a["tactile"][i], a["next_tactile"][i] = tactile, next_tactile
        self.cursor = (i + 1) % self.capacity
        self.size = min(self.size + 1, self.capacity)

    def add_batch(
        self, vectors, tactiles, actions, rewards, terminations, next_vectors, next_tactiles, experts
    ) -> None:
        """One transition per environment of a vector environment, in order (rows of each array;
        ``tactiles`` None without images; ``experts`` a list of teacher actions or Nones)."""
        for i in range(len(vectors)):
            self.add(
                vectors[i],
                None if tactiles is None else tactiles[i],
                actions[i],
                rewards[i],
                terminations[i],
                next_vectors[i],
                None if next_tactiles is None else next_tactiles[i],
                expert=experts[i],
            )

    def sample(
        self, batch_size: int, rng: np.random.Generator, device: str | torch.device = "cpu"
    ) -> dict[str, torch.Tensor | None]:
        """``batch_size`` transitions drawn uniformly (with replacement), as tensors on ``device``."""
        index = rng.integers(0, self.size, batch_size)
        batch = {k: torch.from_numpy(v[index]).to(device) for k, v in self.arrays.items()}
        batch.setdefault("tactile", None)
        batch.setdefault("next_tactile", None)
        return batch

    # -- checkpoints: plain .npy files, read without pickle -----------------------------------
    def save(self, folder: Path) -> None:
        folder.mkdir(parents=True, exist_ok=True)
        for name, array in self.arrays.items():
            np.save(folder / f"{name}.npy", array[: self.size])

    def load(self, folder: Path, size: int, cursor: int) -> None:
        for name, array in self.arrays.items():
            try:
                data = np.load(folder / f"{name}.npy", allow_pickle=False)
            except (OSError, ValueError) as e:
                raise PianobotError(
                    f"checkpoint buffer {folder / (name + '.npy')} is unreadable ({e}): delete the checkpoint folder to start afresh"
                ) from None
            if data.shape[1:] != array.shape[1:] or len(data) != size:
                raise PianobotError(
                    f"checkpoint buffer {folder} does not fit this configuration: delete it to start afresh"
                )
            array[:size] = data
        self.size, self.cursor = size, cursor
