"""The model store: one folder per trained phrase policy, weights in safetensors beside a JSON manifest.

    models/
      <phrase hash>-<config hash>/
        policy.safetensors      actor + encoder weights (what `play` needs)
        manifest.json           phrase, config, steps, evaluation figures, package versions
        checkpoint/             only while training: full state, so an interrupted run resumes
          state.safetensors     every network, optimiser moment and RNG state
          state.json            counters and generator states
          buffer/*.npy          the replay buffer (plain arrays, read without pickle)

Files are written to a temporary name and renamed into place, so a crash never leaves a half
written model; loading never unpickles anything; a corrupt or foreign file is a one-line error.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import torch
from safetensors import SafetensorError
from safetensors.torch import load_file, save_file

from pianobot.config import to_dict
from pianobot.errors import PianobotError
from pianobot.files import atomic_write, move_into_place, temporary_beside

FORMAT = 2
"""Version of the model files (manifest layout and tensor names). Older versions are upgraded on
reading (:func:`upgrade_manifest`), so every model a user has keeps playing.

- 2: one tactile image size, ``config.env.tactile_pool``; every tensor stored once.
- 1: the agent's ``config.sac.tactile_resolution`` overrode ``config.env.tactile_pool``; the
  policy file held the tactile convolutions twice (``encoder.conv.*`` beside
  ``encoder.tactile.0.*``); manifests written before the finger targets carried velocity and
  onsets, and before the score window became optional, lack those fields, which then meant
  ``target_velocity=False``, ``target_onsets=False`` and ``score_input=True``.
"""
POLICY_FILE = "policy.safetensors"
MANIFEST_FILE = "manifest.json"
CHECKPOINT_DIR = "checkpoint"


def config_hash(config) -> str:
    """A stable digest of a (dataclass) training configuration."""
    return hashlib.sha256(json.dumps(to_dict(config), sort_keys=True, default=str).encode()).hexdigest()[:12]


def model_dir(root: Path, key: str, config) -> Path:
    return Path(root) / f"{key}-{config_hash(config)}"


def package_versions() -> dict[str, str]:
    out = {}
    for name in ("pianobot", "torch", "pybullet", "numpy", "gymnasium"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "not installed"
    return out


def save_tensors(tensors: dict[str, torch.Tensor], path: Path, metadata: dict[str, str] | None = None) -> None:
    """safetensors file written atomically."""
    tmp = temporary_beside(path)
    try:
        save_file(tensors, tmp, metadata=metadata)
        move_into_place(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def load_tensors(path: Path) -> dict[str, torch.Tensor]:
    try:
        return load_file(path)
    except FileNotFoundError:
        raise PianobotError(f"model file {path} is missing: retrain the phrase with --force") from None
    except (SafetensorError, OSError, ValueError) as e:
        raise PianobotError(f"model file {path} is not a readable safetensors file ({e}): retrain with --force") from None


def save_policy(folder: Path, tensors: dict[str, torch.Tensor], manifest: dict) -> None:
    """Write weights and manifest; the manifest last, so a folder with a manifest is complete."""
    folder.mkdir(parents=True, exist_ok=True)
    save_tensors(tensors, folder / POLICY_FILE, metadata={"format": str(FORMAT)})
    manifest = {"format": FORMAT, **manifest, "versions": package_versions()}
    atomic_write(folder / MANIFEST_FILE, json.dumps(manifest, indent=2, default=str) + "\n")


def upgrade_manifest(manifest: dict) -> dict:
    """A manifest of any earlier :data:`FORMAT` as the current format says it (a new dict)."""
    manifest = json.loads(json.dumps(manifest))  # a deep copy
    if manifest.get("format") == 1:
        config = manifest["config"]
        env, sac = config["env"], config["sac"]
        env["tactile_pool"] = sac.pop("tactile_resolution", env.get("tactile_pool"))
        env.setdefault("target_velocity", False)
        env.setdefault("target_onsets", False)
        sac.setdefault("score_input", True)
        manifest["format"] = 2
    return manifest


def read_manifest(folder: Path) -> dict:
    """The manifest of a trained policy, upgraded to the current format."""
    path = folder / MANIFEST_FILE
    try:
        manifest = json.loads(path.read_text())
    except FileNotFoundError:
        raise PianobotError(f"{folder} holds no {MANIFEST_FILE}: it is not a trained pianobot policy") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise PianobotError(f"{path} is not a readable manifest ({e}): retrain the phrase with --force") from None
    if not isinstance(manifest, dict) or manifest.get("format") not in range(1, FORMAT + 1):
        raise PianobotError(f"{path} is not a pianobot model manifest (formats 1 to {FORMAT}): retrain the phrase with --force")
    if not isinstance(manifest.get("config"), dict) or not all(isinstance(manifest["config"].get(k), dict) for k in ("env", "sac")):
        raise PianobotError(f"{path} does not record the configuration its policy was trained with: retrain the phrase with --force")
    return upgrade_manifest(manifest)


def is_trained(folder: Path) -> bool:
    return (folder / MANIFEST_FILE).exists() and (folder / POLICY_FILE).exists()


def find_policies(root: Path, key: str) -> list[Path]:
    """Trained policy folders for a phrase hash (or task key), newest first."""
    root = Path(root)
    if not root.is_dir():
        return []
    found = [d for d in root.iterdir() if d.is_dir() and d.name.startswith(f"{key}-") and is_trained(d)]
    return sorted(found, key=lambda d: (d / MANIFEST_FILE).stat().st_mtime, reverse=True)


# -- checkpoints ------------------------------------------------------------------------------
def save_checkpoint(folder: Path, tensors: dict[str, torch.Tensor], state: dict, buffer) -> None:
    """Write a complete checkpoint beside the old one, then swap it in."""
    final = folder / CHECKPOINT_DIR
    staging = folder / f".{CHECKPOINT_DIR}.new"
    shutil.rmtree(staging, ignore_errors=True)
    staging.mkdir(parents=True)
    save_tensors(tensors, staging / "state.safetensors")
    buffer.save(staging / "buffer")
    (staging / "state.json").write_text(json.dumps(state) + "\n")
    old = folder / f".{CHECKPOINT_DIR}.old"
    shutil.rmtree(old, ignore_errors=True)
    if final.exists():
        final.rename(old)
    staging.rename(final)
    shutil.rmtree(old, ignore_errors=True)


def load_checkpoint(folder: Path) -> tuple[dict[str, torch.Tensor], dict, Path] | None:
    final = folder / CHECKPOINT_DIR
    if not (final / "state.json").exists():
        return None
    try:
        state = json.loads((final / "state.json").read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise PianobotError(f"checkpoint {final} is unreadable ({e}): delete it to start afresh") from None
    return load_tensors(final / "state.safetensors"), state, final / "buffer"


def drop_checkpoint(folder: Path) -> None:
    shutil.rmtree(folder / CHECKPOINT_DIR, ignore_errors=True)
