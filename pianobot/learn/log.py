"""Training logs beside the policy, as Stable-Baselines3 and CleanRL write them.

- ``training.csv``: one row per episode: step, wall-clock seconds, the episode's return, the last
  update's losses, temperature, entropy and Q, and, where an evaluation ran, its note F1,
  velocity error and return (a fine-tuning run's evaluation of its start policy, before any
  episode, is a row of its own at step 0, episode 0, without a return);
- ``tensorboard/``: the same as TensorBoard scalars, when ``tensorboard`` is installed
  (``pip install pianobot[tensorboard]``);
- ``learning.png``: the learning curves, drawn when the run ends.

A resumed run keeps the rows up to its checkpoint and drops those an interrupted run wrote after
it (those steps are trained again), so the log reads as one uninterrupted run.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

from pianobot.files import atomic_write

LOG_FILE = "training.csv"
PLOT_FILE = "learning.png"
TENSORBOARD_DIR = "tensorboard"
COLUMNS = (
    "step",
    "episode",
    "seconds",
    "return",
    "critic_loss",
    "actor_loss",
    "alpha",
    "entropy",
    "q",
    "cloning_loss",
    "eval_f1",
    "eval_velocity_mae",
    "eval_return",
)


class TrainingLog:
    """``start(resumed_at)`` once the run knows where it starts, ``row(...)`` per episode, ``plot()`` at the end."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.file = None
        self.writer = None
        self.board = None

    def __enter__(self) -> TrainingLog:
        return self

    def __exit__(self, *exc) -> None:
        if self.file is not None:
            self.file.close()
        if self.board is not None:
            self.board.close()

    def start(self, resumed_at: int | None) -> None:
        """Open the log: afresh, or (``resumed_at``: the checkpoint's step) keeping the rows up to it."""
        path = self.folder / LOG_FILE
        kept = []
        if resumed_at is not None and path.exists():
            with open(path, newline="") as old:
                kept = [row for row in csv.DictReader(old) if int(row["step"]) <= resumed_at]
        self.file = open(path, "w", newline="")
        self.writer = csv.DictWriter(self.file, COLUMNS, extrasaction="ignore")
        self.writer.writeheader()
        self.writer.writerows(kept)
        self.file.flush()
        try:
            from torch.utils.tensorboard import SummaryWriter
        except ImportError:  # tensorboard is an optional extra
            return
        purge = None if resumed_at is None else resumed_at + 1
        self.board = SummaryWriter(str(self.folder / TENSORBOARD_DIR), purge_step=purge)

    def row(
        self,
        step: int,
        episode: int,
        seconds: float,
        episode_return: float,
        losses: dict | None,
        evaluation: dict | None,
    ) -> None:
        values = {"step": step, "episode": episode, "seconds": round(seconds, 2), "return": round(episode_return, 4)}
        values.update({k: round(v, 6) for k, v in (losses or {}).items() if k in COLUMNS})
        if evaluation is not None:
            values.update({f"eval_{k}": evaluation[k] for k in ("f1", "velocity_mae", "return")})
        self.writer.writerow(values)
        self.file.flush()
        if self.board is not None:
            for key, value in values.items():
                if key not in ("step", "episode") and value is not None:
                    self.board.add_scalar(key.replace("eval_", "eval/"), value, step)

    def evaluation(self, step: int, seconds: float, evaluation: dict, episode: int = 0) -> None:
        """An evaluation that no episode's end carries (a fine-tuning run's start policy, at step 0;
        a DAgger round's end, after ``episode`` episodes): a row of its own, with no return or losses."""
        values = {"step": step, "episode": episode, "seconds": round(seconds, 2)}
        values.update({f"eval_{k}": evaluation[k] for k in ("f1", "velocity_mae", "return")})
        self.writer.writerow(values)
        self.file.flush()
        if self.board is not None:
            for key, value in values.items():
                if key.startswith("eval_") and value is not None:
                    self.board.add_scalar(key.replace("eval_", "eval/"), value, step)

    def plot(self) -> Path:
        """Draw the learning curves from the log to ``learning.png`` beside it."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        with open(self.folder / LOG_FILE, newline="") as log:
            rows = list(csv.DictReader(log))
        evaluated = [r for r in rows if r["eval_f1"]]
        figure, (returns, f1) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
        episodes = [r for r in rows if r["return"]]  # (a start policy's evaluation has no return)
        returns.plot([int(r["step"]) for r in episodes], [float(r["return"]) for r in episodes], lw=0.8)
        returns.set_ylabel("episode return")
        f1.plot([int(r["step"]) for r in evaluated], [float(r["eval_f1"]) for r in evaluated], marker="o")
        f1.set_ylabel("evaluation note F1")
        f1.set_ylim(-0.05, 1.05)
        f1.set_xlabel("environment steps")
        figure.tight_layout()
        image = io.BytesIO()
        figure.savefig(image, format="png", dpi=80)
        plt.close(figure)
        return atomic_write(self.folder / PLOT_FILE, image.getvalue())
