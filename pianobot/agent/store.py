"""The model store: one folder per trained phrase policy, weights in safetensors beside a JSON manifest.

    models/
      <phrase hash>-<config hash>/
        policy.safetensors      actor + encoder weights (what `play` needs)
        critic.safetensors      twin Q heads + temperature (what fine-tuning starts from besides)
        manifest.json           phrase, config, steps, evaluation figures, package versions
        checkpoint/<step>/      only while training: full state, so an interrupted run resumes
          state.safetensors     every network, optimiser moment and RNG state
          state.json            counters and generator states
          buffer/*.npy          the replay buffer (plain arrays, read without pickle)
        .lock                   held by the process training into the folder
      general-plays.json        the phrases the general policy plays: no policy of their own (a
                                phrase whose training kept its start: the general policy played
                                it as well as anything trained), or a folder whose policy made
                                its piece play worse (:func:`general_plays`)

Files are written to a temporary name and renamed into place, so a crash never leaves a half
written model; loading never unpickles anything; a corrupt or foreign file is a one-line error.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import os
import shutil
import time
from datetime import datetime, timezone
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import TYPE_CHECKING

from safetensors import SafetensorError

from pianobot.config import to_dict
from pianobot.errors import PianobotError, SettingError
from pianobot.files import atomic_write, move_into_place, temporary_beside

if TYPE_CHECKING:  # torch is imported by the functions that read and write tensors: finding models needs none
    import torch

FORMAT = 2
"""Version of the model files (manifest layout and tensor names). Older versions are upgraded on
reading (:func:`upgrade_manifest`), so every model a user has keeps playing.

- 2: one tactile image size, ``config.env.tactile_pool``; every tensor stored once. Added
  since, absent from the manifests written before them, where their absence means what those
  runs did: ``config.from_general`` (false: trained from scratch) and ``start`` (null: the
  policy training began from, fine-tuning; docs/training.md), ``config.finetune_until_f1``
  (unused without ``from_general``), ``config.envs`` and ``config.device`` (1, auto),
  ``config.sac.actor`` ('mlp'), ``saved`` (when the policy was stored: the manifest file's
  modification time stands in), ``kept`` ('trained': a stored policy; a run whose start policy
  already played its phrase, or was never beaten, now stores none, says ``kept: 'start'`` and is
  recorded in :data:`GENERAL_INDEX`; before, it stored a copy of the start); the file
  ``critic.safetensors`` (missing: the policy cannot pass its critic on to a fine-tuning run,
  which then begins with fresh Q heads); ``simulator`` (:data:`pianobot.env.VERSION` of the
  environment the run that chose the policy trained and evaluated it on; missing, it is read as
  1 for a policy ``saved`` after v1's physics came in, :data:`V1_SINCE`, else 0, v0's: a
  manifest without ``saved`` predates v1).
- 1: the agent's ``config.sac.tactile_resolution`` overrode ``config.env.tactile_pool``; the
  policy file held the tactile convolutions twice (``encoder.conv.*`` beside
  ``encoder.tactile.0.*``); manifests written before the finger targets carried velocity and
  onsets, and before the score window became optional, lack those fields, which then meant
  ``target_velocity=False``, ``target_onsets=False`` and ``score_input=True``.
"""
V1_SINCE = "2026-11-24T20:31:14+00:00"
"""When the simulator's v1 physics came in (its commit): a manifest without ``simulator`` saved
after it was trained on v1 (:func:`upgrade_manifest`)."""
POLICY_FILE = "policy.safetensors"
CRITIC_FILE = "critic.safetensors"
MANIFEST_FILE = "manifest.json"
CHECKPOINT_DIR = "checkpoint"
LOCK_FILE = ".lock"


def config_hash(config) -> str:
    """A stable digest of a (dataclass) training configuration. Its fields marked
    ``metadata={"runtime": True}`` say how a run executes, not what it trains (``TrainConfig.envs``,
    ``device``), or ``metadata={"start": True}`` where it begins and when fine-tuning stops
    (``TrainConfig.from_general``, ``finetune_until_f1``): they are left out, so that the same
    training finds the same folder however it runs, and a phrase's folder holds one policy for its
    configuration, fine-tuned or trained from scratch (the manifest's ``start`` says which).
    A SAC run (``TrainConfig.learner`` 'sac') leaves out ``learner`` and the DAgger settings it
    does not use, so that its folder keeps the name it had before there was another learner; an
    agent with the default actor (``SACConfig.actor`` 'mlp') leaves out ``sac.actor`` likewise, a DAgger run
    without the hold guard (``DaggerConfig.hold_guard`` False) that setting, a run
    of the Allegro-like hand (``HandSpec.model`` 'allegro') its hand model, and a run whose foot
    follows the score (``EnvConfig.pedal_action`` False) the pedal's settings."""
    runtime = {f.name for f in dataclasses.fields(config) if f.metadata.get("runtime") or f.metadata.get("start")}
    fields = {k: v for k, v in to_dict(config).items() if k not in runtime}
    if fields.get("learner") == "sac":
        fields.pop("learner")
        fields.pop("dagger", None)
    if isinstance(fields.get("dagger"), dict) and not fields["dagger"].get("hold_guard", True):
        fields["dagger"] = {k: v for k, v in fields["dagger"].items() if k != "hold_guard"}
    if isinstance(fields.get("sac"), dict) and fields["sac"].get("actor") == "mlp":
        fields["sac"] = {k: v for k, v in fields["sac"].items() if k != "actor"}
    env = fields.get("env", {})
    if isinstance(env, dict) and not env.get("pedal_action", True):  # (the pedal before it could be an action)
        env.pop("pedal_action")
        env.get("reward", {}).pop("pedal_weight", None)
    spec = fields.get("env", {}).get("world", {}).get("hand", {}).get("spec", {})
    if isinstance(spec, dict) and spec.get("model") == "allegro":  # (the hand model before there were others)
        spec.pop("model")
    return hashlib.sha256(json.dumps(fields, sort_keys=True, default=str).encode()).hexdigest()[:12]


def model_dir(root: Path, key: str, config) -> Path:
    return Path(root) / f"{key}-{config_hash(config)}"


def task_key(task: str, version: int = 1) -> str:
    """The key of a task family's policy folders (``task-<name>-<config hash>``; after the family's
    first version ``task-<name>-v<version>-<config hash>``). A key is also the prefix of its later
    versions' keys, so :func:`find_policies` with a version 1 key finds every version's folders."""
    return f"task-{task}" if version == 1 else f"task-{task}-v{version}"


def file_digest(path: Path) -> str:
    """SHA-256 of a file's bytes (hex): which weights a policy is, wherever its folder lies."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


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
    from safetensors.torch import save_file

    tmp = temporary_beside(path)
    try:
        save_file(tensors, tmp, metadata=metadata)
        move_into_place(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def load_tensors(path: Path) -> dict[str, torch.Tensor]:
    """A safetensors file's tensors (nothing is unpickled); a missing or unreadable file is one line."""
    from safetensors.torch import load_file

    try:
        return load_file(path)
    except FileNotFoundError:
        raise SettingError(f"model file {path} is missing: retrain the phrase with jobs.force", "jobs.force") from None
    except (SafetensorError, OSError, ValueError) as e:
        raise SettingError(
            f"model file {path} is not a readable safetensors file ({e}): retrain with jobs.force", "jobs.force"
        ) from None


def save_policy(
    folder: Path, tensors: dict[str, torch.Tensor], manifest: dict, critic: dict[str, torch.Tensor] | None = None
) -> None:
    """Write weights (``critic``: the Q heads and temperature too, :meth:`SAC.critic_tensors`) and
    manifest; the manifest last, so a folder with a manifest is complete."""
    folder.mkdir(parents=True, exist_ok=True)
    save_tensors(tensors, folder / POLICY_FILE, metadata={"format": str(FORMAT)})
    if critic:
        save_tensors(critic, folder / CRITIC_FILE, metadata={"format": str(FORMAT)})
    else:  # (a forced retrain must not leave an older run's critic beside the new policy)
        (folder / CRITIC_FILE).unlink(missing_ok=True)
    save_manifest(folder, manifest)


def save_manifest(folder: Path, manifest: dict) -> None:
    """Write ``manifest`` (with the format, the time and the package versions) into ``folder``;
    alone, it records a run that kept its start policy and stored none (:func:`kept_start`)."""
    folder.mkdir(parents=True, exist_ok=True)
    saved = datetime.now(timezone.utc).isoformat(timespec="seconds")
    from pianobot.env import VERSION  # (the gymnasium ids only: no simulator is imported)

    manifest = {"format": FORMAT, "simulator": VERSION, **manifest, "saved": saved, "versions": package_versions()}
    atomic_write(folder / MANIFEST_FILE, json.dumps(manifest, indent=2, default=str) + "\n")


def kept_start(folder: Path) -> bool:
    """Whether a finished run in ``folder`` kept its start policy: a manifest that says so
    (``"kept": "start"``) and no policy file."""
    if (folder / POLICY_FILE).exists():
        return False
    try:
        return json.loads((folder / MANIFEST_FILE).read_text()).get("kept") == "start"
    except (OSError, ValueError, AttributeError):
        return False


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
    if isinstance(manifest.get("config"), dict):  # fields added within format 2 (see FORMAT)
        manifest["config"].setdefault("from_general", False)
    manifest.setdefault("start", None)
    manifest.setdefault("kept", "trained")  # (a stored policy was trained, or copied from its start before ``kept``)
    if "simulator" not in manifest:
        saved = manifest.get("saved")
        manifest["simulator"] = int(isinstance(saved, str) and _utc(saved) >= _utc(V1_SINCE))
    return manifest


def _utc(stamp: str) -> datetime:
    try:
        return datetime.fromisoformat(stamp).astimezone(timezone.utc)
    except ValueError:
        return datetime.min.replace(tzinfo=timezone.utc)


def simulator(folder: Path) -> int:
    """The simulator version (:data:`pianobot.env.VERSION`) the policy in ``folder`` was trained on."""
    return read_manifest(folder)["simulator"]


def read_manifest(folder: Path) -> dict:
    """The manifest of a trained policy, upgraded to the current format."""
    path = folder / MANIFEST_FILE
    try:
        manifest = json.loads(path.read_text())
    except FileNotFoundError:
        raise PianobotError(f"{folder} holds no {MANIFEST_FILE}: it is not a trained pianobot policy") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise SettingError(
            f"{path} is not a readable manifest ({e}): retrain the phrase with jobs.force", "jobs.force"
        ) from None
    if not isinstance(manifest, dict) or manifest.get("format") not in range(1, FORMAT + 1):
        raise SettingError(
            f"{path} is not a pianobot model manifest (formats 1 to {FORMAT}): retrain the phrase with jobs.force",
            "jobs.force",
        )
    if not isinstance(manifest.get("config"), dict) or not all(
        isinstance(manifest["config"].get(k), dict) for k in ("env", "sac")
    ):
        raise SettingError(
            f"{path} does not record the configuration its policy was trained with: retrain the phrase with jobs.force",
            "jobs.force",
        )
    return upgrade_manifest(manifest)


def is_trained(folder: Path) -> bool:
    return (folder / MANIFEST_FILE).exists() and (folder / POLICY_FILE).exists()


def trained_keys(root: Path) -> set[str]:
    """The phrase hashes (and task keys) that have a trained policy in ``root``: one listing of the
    folder, for asking about many phrases at once."""
    root = Path(root)
    if not root.is_dir():
        return set()
    return {d.name.rsplit("-", 1)[0] for d in root.iterdir() if d.is_dir() and "-" in d.name and is_trained(d)}


def saved_at(folder: Path) -> str:
    """When the policy in ``folder`` was stored (UTC, ISO 8601): its manifest's ``saved``, else (a
    manifest written before it was recorded) the manifest file's modification time."""
    try:
        saved = json.loads((folder / MANIFEST_FILE).read_text()).get("saved")
    except (OSError, ValueError, AttributeError):
        saved = None
    if isinstance(saved, str):
        return saved
    mtime = (folder / MANIFEST_FILE).stat().st_mtime
    return datetime.fromtimestamp(mtime, timezone.utc).isoformat(timespec="seconds")


def find_policies(root: Path, key: str) -> list[Path]:
    """Trained policy folders for a phrase hash (or task key), newest first (:func:`saved_at`:
    a clone's files all have the time of the checkout, the manifests keep when they were trained)."""
    root = Path(root)
    if not root.is_dir():
        return []
    found = [d for d in root.iterdir() if d.is_dir() and d.name.startswith(f"{key}-") and is_trained(d)]
    return sorted(found, key=saved_at, reverse=True)


DEFAULT_STORE = Path("models")
"""The model store commands read and write by default (``--models``): ``models`` in the working folder,
which may be absent (the packaged policies then play)."""

GENERAL_INDEX = "general-plays.json"
"""The store's index of the phrases the general policy plays (:func:`general_plays`)."""


def general_plays(root: Path) -> dict[str, dict]:
    """The phrases the general policy plays, by folder name (``<phrase hash>-<config hash>``):
    each with ``why`` (a phrase whose training kept its start, the general policy, so none was
    stored; or a policy of its own that made its piece play worse, and is not used)
    and the general policy's ``sha256``. A missing or unreadable index is an empty one: a phrase
    then is what its folder says."""
    try:
        found = json.loads((Path(root) / GENERAL_INDEX).read_text())
    except (OSError, ValueError):
        return {}
    return {k: v for k, v in found.items() if isinstance(v, dict)} if isinstance(found, dict) else {}


def mark_general_plays(root: Path, entries: dict[str, dict | None]) -> None:
    """Record (a dict) or forget (None) that the general policy plays these folders' phrases;
    written atomically, merged with what the index holds."""
    index = general_plays(root)
    for key, entry in entries.items():
        if entry is None:
            index.pop(key, None)
        else:
            index[key] = entry
    Path(root).mkdir(parents=True, exist_ok=True)
    atomic_write(Path(root) / GENERAL_INDEX, json.dumps(index, indent=2, sort_keys=True) + "\n")


JUDGED_INDEX = "judged.json"
"""The store's index of the phrase policies ``pianobot train`` judged and kept (:func:`judged`)."""


def judged(root: Path) -> dict[str, dict]:
    """The phrase policies whose piece played better with them than with the general policy
    alone, by folder name: each with the general policy judged beside (``path``, ``sha256``). A
    missing or unreadable index is an empty one."""
    try:
        found = json.loads((Path(root) / JUDGED_INDEX).read_text())
    except (OSError, ValueError):
        return {}
    return {k: v for k, v in found.items() if isinstance(v, dict)} if isinstance(found, dict) else {}


def mark_judged(root: Path, entries: dict[str, dict | None]) -> None:
    """Record (a dict: the general policy judged beside) or forget (None) a verdict that kept these
    folders' policies; written atomically, merged with what the index holds."""
    index = judged(root)
    for name, entry in entries.items():
        if entry is None:
            index.pop(name, None)
        else:
            index[name] = entry
    atomic_write(Path(root) / JUDGED_INDEX, json.dumps(index, indent=2, sort_keys=True) + "\n")


def covered_keys(root: Path) -> set[str]:
    """The phrase hashes that play without training: a policy of their own, or the general policy's
    by the index (:func:`general_plays`)."""
    return trained_keys(root) | {key.rsplit("-", 1)[0] for key in general_plays(root)}


# -- checkpoints ------------------------------------------------------------------------------
def _checkpoints(folder: Path) -> list[Path]:
    """The complete checkpoints in ``folder``, oldest first (one is complete once renamed from
    its ``.tmp`` name, which happens after everything in it was written)."""
    root = folder / CHECKPOINT_DIR
    if not root.is_dir():
        return []
    if (root / "state.json").exists():  # the single checkpoint folder of versions before 0.2
        return [root]
    return sorted((d for d in root.iterdir() if d.is_dir() and d.name.isdigit()), key=lambda d: int(d.name))


def save_checkpoint(folder: Path, tensors: dict[str, torch.Tensor], state: dict, buffer) -> None:
    """Write a complete checkpoint of ``state["step"]``, then drop the older ones.

    It is written under a temporary name and renamed into place in one step, and older
    checkpoints are removed only after that: a kill at any instant leaves the newest complete
    checkpoint to resume from, losing at most the steps since it."""
    root = folder / CHECKPOINT_DIR
    final = root / f"{state['step']:010d}"
    staging = root / f"{final.name}.tmp"
    shutil.rmtree(staging, ignore_errors=True)
    staging.mkdir(parents=True)
    save_tensors(tensors, staging / "state.safetensors")
    buffer.save(staging / "buffer")
    atomic_write(staging / "state.json", json.dumps(state) + "\n")
    shutil.rmtree(final, ignore_errors=True)  # (only if a run was cut off just after writing this very step)
    staging.rename(final)
    for other in root.iterdir():
        if other != final:
            shutil.rmtree(other, ignore_errors=True) if other.is_dir() else other.unlink(missing_ok=True)


def _read_newest(folder: Path, read):
    """``(newest checkpoint, read(it))``, or None when there is none. Each checkpoint is read
    from the one listing that found it, so its parts always belong together. A running training
    replaces its checkpoint (and removes it when it finishes) while a report may be reading it, a
    few milliseconds of files going one by one: a read that fails is tried again from a fresh
    listing a moment later, and only a newest checkpoint that fails twice is reported unreadable."""
    failed = None
    for _ in range(5):
        found = _checkpoints(folder)
        if not found:
            return None
        newest = found[-1]
        try:
            return newest, read(newest)
        except (OSError, ValueError, SafetensorError) as e:
            if newest == failed:
                raise PianobotError(f"checkpoint {newest} is unreadable ({e}): delete it to start afresh") from None
            failed = newest
            time.sleep(0.2)
    raise PianobotError(f"the checkpoints in {folder} kept changing while being read: try again")


def checkpoint_state(folder: Path) -> dict | None:
    """The counters of the newest checkpoint (step, evaluations, ...), or None: cheap, reads no tensors."""
    found = _read_newest(folder, lambda newest: json.loads((newest / "state.json").read_text()))
    return None if found is None else found[1]


def load_checkpoint(folder: Path) -> tuple[dict[str, torch.Tensor], dict, Path] | None:
    """(tensors, state, buffer folder) of the newest complete checkpoint, or None."""

    from safetensors.torch import load_file

    def read(newest: Path):
        return json.loads((newest / "state.json").read_text()), load_file(newest / "state.safetensors")

    found = _read_newest(folder, read)
    if found is None:
        return None
    newest, (state, tensors) = found
    return tensors, state, newest / "buffer"


def drop_checkpoint(folder: Path) -> None:
    shutil.rmtree(folder / CHECKPOINT_DIR, ignore_errors=True)


def remove_temporary_files(folder: Path) -> None:
    """Remove what an interrupted write left in ``folder`` (temporary policy and manifest files)."""
    if folder.is_dir():
        for leftover in folder.glob(".*.tmp*"):
            if leftover.is_file():
                leftover.unlink(missing_ok=True)


@contextlib.contextmanager
def training_lock(folder: Path):
    """Hold ``folder`` for one training run: a second run on the same folder (another
    ``pianobot train`` on the same models) is refused with a clear error instead of sharing its
    checkpoint. The operating system releases the lock when the process ends, however it ends."""
    import fcntl

    folder.mkdir(parents=True, exist_ok=True)
    with open(folder / LOCK_FILE, "a+") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            lock.seek(0)
            holder = lock.read().strip() or "another process"
            raise SettingError(
                f"{folder} is being trained by {holder}: wait for it to finish, or train into another store.models folder",
                "store.models",
            ) from None
        lock.seek(0)
        lock.truncate()
        lock.write(f"pianobot process {os.getpid()}")
        lock.flush()
        try:
            yield
        finally:
            lock.seek(0)
            lock.truncate()
            fcntl.flock(lock, fcntl.LOCK_UN)
