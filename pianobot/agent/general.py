"""The general policy: one policy trained on the ``melody`` task family (random one-hand phrases,
docs/training.md) or the ``parts`` family (one hand's whole parts of random two-hand
pieces), which plays the phrases that have no policy of their own and is where the
training of a new phrase begins (fine-tuning).

Where it lives: the committed general policy ships inside the package (:data:`PACKAGED`), so it
is found from any folder and from a wheel install; a user's model store, where ``pianobot train
--task melody`` (or ``--task parts``) puts one (folder ``task-melody-<config hash>``, or
``task-parts-...``), comes first. ``pianobot play``
and ``pianobot train`` take the newest such folder in the store whose environment is the one they
need, then the packaged one, and ``--general-policy DIR`` names another (any trained policy folder). It plays consecutive phrases without a policy of their own as one stretch:
the sliding score window of that stretch, and its finger targets (:mod:`pianobot.perform.compose`).

A general policy and the phrases it plays or starts must share one environment (the
observations and actions it was trained with): :func:`difference` names the first field in which
two configurations differ, and :func:`find_general` refuses, in one line naming the option to
change, a general policy that does not fit.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pianobot.agent import store
from pianobot.agent.config import SACConfig
from pianobot.agent.policy import policy_configs
from pianobot.config import to_dict
from pianobot.env.piano import EnvConfig
from pianobot.errors import PianobotError, SettingError
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.tasks import MELODY, PARTS

if TYPE_CHECKING:
    import torch

GENERAL_TASK = MELODY
"""The task family whose policy is the general policy: random one-hand phrases."""
GENERAL_KEY = store.task_key(GENERAL_TASK)
"""Its folders' key in the model store: ``task-melody-<config hash>``."""
GENERAL_KEYS = (GENERAL_KEY, store.task_key(PARTS))
"""The folders' keys of every general policy: the ``melody`` family's, and the ``parts`` family's
(one hand's parts of random two-hand pieces: a general policy too; the key finds every version's
folders, ``task-parts-``, ``task-parts-v2-``, ``task-parts-v3-``)."""
PACKAGED = Path(__file__).resolve().parent.parent / "policies"
"""The policies that ship with pianobot (package data): the committed general policy (a
``task-melody`` folder), and the ``task-parts`` folders: the three-finger hand's policy for both
hands of a two-hand piece (:func:`parts_policy`) and the thumb's (fingers 1-4), which plays
every piece read for that hand."""
PARTS_KEY = store.task_key(PARTS)
"""The packaged parts policies' key: the ``parts`` family's (any version), which learnt hands'
whole parts (chords, held notes under a moving voice, bass lines)."""

NETWORK_FIELDS = ("hidden", "actor", "score_input", "score_features", "tactile_channels", "tactile_features")
"""The :class:`SACConfig` fields that shape the networks: a start policy's must be the run's."""

SETTINGS = (
    "env.tactile",
    "env.actuated",
    "env.world.control",
    "env.world.keyboard.spec",
    "env.world.hand.spec",
    "env.reward.kind",
    "env.reward.fingering_gate",
    "sac.actor",
    "sac",
)
"""The settings a difference is named by (a field's dotted path under :class:`TrainConfig`, as
``train.<path>``, the longest that contains it): the command line says which option sets each."""


def _difference(ours: Any, theirs: Any, path: str) -> tuple[str, Any, Any] | None:
    if isinstance(ours, dict) and isinstance(theirs, dict):
        for key in list(ours) + [k for k in theirs if k not in ours]:
            found = _difference(ours.get(key), theirs.get(key), f"{path}.{key}")
            if found is not None:
                return found
        return None
    return None if ours == theirs else (path, ours, theirs)


def difference(
    ours: EnvConfig, theirs: EnvConfig, our_sac: SACConfig | None = None, their_sac: SACConfig | None = None
) -> tuple[str, Any, Any] | None:
    """The first field (dotted path, our value, theirs) in which two environments differ, or
    (given both) two agents' networks; None when a policy of one fits the other. Whether the
    simulation is shown (``world.gui``) does not count."""
    mine, yours = to_dict(ours), to_dict(theirs)
    mine["world"].pop("gui"), yours["world"].pop("gui")
    found = _difference(mine, yours, "env")
    if found is None and our_sac is not None and their_sac is not None:
        nets = [{k: v for k, v in to_dict(c).items() if k in NETWORK_FIELDS} for c in (our_sac, their_sac)]
        found = _difference(nets[0], nets[1], "sac")
    return found


def plays_keyboard(env: EnvConfig, sac: SACConfig, keyboard: Any) -> bool:
    """Whether a policy trained with ``env`` and ``sac`` plays on ``keyboard`` (a spec): its own
    keyboard, or one of at least as many keys where nothing its networks read has the number of
    keys for its size (no score window, no keys' observations) and its wrist slides rather than
    picks a key. Its fingers' targets are where their notes lie from them, its wrist's position a
    share of the keyboard's width: the keys' shapes and the hand are the world's, not the
    keyboard's. (Measured on parts wider than 24 keys: docs/play.md, "Both hands".)"""
    own = env.world.keyboard.spec
    if keyboard == own:
        return True
    wide = keyboard.count >= own.count
    return wide and not sac.score_input and not env.key_observations and not env.world.discrete_wrist


def on_keyboard(env: EnvConfig, sac: SACConfig, keyboard: Any) -> EnvConfig:
    """``env`` on ``keyboard`` where its policy plays it (:func:`plays_keyboard`); else ``env``."""
    if not plays_keyboard(env, sac, keyboard):
        return env
    return replace(env, world=replace(env.world, keyboard=replace(env.world.keyboard, spec=keyboard)))


def setting_for(path: str) -> str:
    """The setting (``train.<dotted path>``) a differing field belongs to, else the field itself."""
    found = next((s for s in SETTINGS if path == s or path.startswith(s + ".")), path)
    return f"train.{found}"


def _show(value: Any) -> str:
    if isinstance(value, dict):
        return ", ".join(f"{k} {_show(v)}" for k, v in value.items())
    if isinstance(value, (list, tuple)):
        return ",".join(map(str, value))
    return str(value).lower() if isinstance(value, bool) else str(value)


def explain(folder: Path, found: tuple[str, Any, Any], ours: str) -> str:
    """'the general policy F was trained with PATH X, OURS with Y (SETTING)': the setting by its
    field (:func:`setting_for`), which the command line names as its option."""
    path, mine, theirs = found
    return (
        f"the general policy {folder} was trained with {path} {_show(theirs)}, {ours} with {_show(mine)} "
        f"({setting_for(path)})"
    )


def general_candidates(models: Path | None) -> list[Path]:
    """Every general policy there is: the newest first in ``models`` (the user's store), then the
    packaged general policy (:data:`PACKAGED`'s ``task-melody`` folder), then the packaged
    ``task-parts`` policies, which play a one-hand piece only where no policy before them fits it
    (the packaged thumb's, for a hand with fingers 1-4; :func:`parts_policy` gives them both
    hands of a two-hand piece)."""
    found = _newest_first(models) if models is not None else []
    packaged = _newest_first(PACKAGED, (GENERAL_KEY,)) + _newest_first(PACKAGED, (PARTS_KEY,))
    return found + [p for p in packaged if p.resolve() not in {f.resolve() for f in found}]


def parts_policy(models: Path | None, keyboard: Any = None, hand: Any = HandSpec()) -> Path | None:
    """The general policy that plays both hands of a two-hand piece by default (one-hand pieces have
    the general policy, :func:`general_candidates`): the packaged ``parts`` policy for ``hand``'s
    fingers (a spec; default the three-finger hand), when the user's store holds no general policy
    of its own for ``keyboard`` (a spec, None: any) and ``hand`` (such a one plays both hands) and
    the packaged one plays them (:func:`plays_keyboard`). None: both hands have the general policy.
    Why one policy for both hands: docs/benchmarks.md, "Two hands"."""

    def fits(folder: Path) -> bool:
        env, sac = policy_configs(folder)
        return (keyboard is None or plays_keyboard(env, sac, keyboard)) and hand == env.world.hand.spec

    if models is not None and any(fits(folder) for folder in _newest_first(Path(models))):
        return None
    return next((folder for folder in _newest_first(PACKAGED, (PARTS_KEY,)) if fits(folder)), None)


def _newest_first(root: Path, keys: tuple[str, ...] = GENERAL_KEYS) -> list[Path]:
    found = [folder for key in keys for folder in store.find_policies(root, key)]
    return sorted(found, key=store.saved_at, reverse=True)


def find_general(
    models: Path,
    env: EnvConfig | None = None,
    sac: SACConfig | None = None,
    path: Path | None = None,
    ours: str = "this run",
    remedy: str = "",
) -> Path | None:
    """The general policy's folder: ``path`` when given (any trained policy), else the newest
    ``task-melody`` or ``task-parts`` policy in ``models``, then the packaged one (:func:`general_candidates`), that
    fits ``env`` (and ``sac``'s networks, when given); None when there is none. A policy of the
    user's (``path``, or in ``models``) that does not fit is refused: a one-line
    :class:`PianobotError` naming the first field that differs (and its option) and ``remedy``.
    The packaged one that does not fit is passed over (a run with other options than the
    committed policy's trains from scratch, as it would with no general policy), and so is one in
    ``models`` of another hand model (a body it cannot drive, not an option mistyped)."""
    if path is not None:
        if not store.is_trained(Path(path)):
            raise PianobotError(
                f"general.path {path}: not a trained policy folder (one holding {store.POLICY_FILE} and "
                f"{store.MANIFEST_FILE}, e.g. {Path(models) / GENERAL_KEY}-<config hash>)"
            )
        candidates = [Path(path)]
    else:
        candidates = general_candidates(models)
    if not candidates:
        return None
    if env is None:
        return candidates[0]
    first = None
    for folder in candidates:
        their_env, their_sac = policy_configs(folder)
        if path is None and their_env.world.hand.spec.model != env.world.hand.spec.model:
            continue
        their_env = on_keyboard(their_env, their_sac, env.world.keyboard.spec)
        found = difference(env, their_env, sac, their_sac if sac is not None else None)
        if found is None:
            return folder
        if path is not None or PACKAGED not in folder.resolve().parents:
            first = first or (folder, found)
    if first is None:
        return None
    folder, found = first
    raise SettingError(explain(folder, found, ours) + (f": {remedy}" if remedy else ""), setting_for(found[0]))


def describe(folder: Path) -> dict:
    """What a manifest records of the policy a run started from, or a performance used: its
    folder, the SHA-256 of its weights, and whether it passed on a critic."""
    return {
        "path": str(folder),
        "sha256": store.file_digest(Path(folder) / store.POLICY_FILE),
        "critic": (Path(folder) / store.CRITIC_FILE).exists(),
    }


def start_tensors(folder: Path) -> tuple[dict[str, torch.Tensor], dict[str, torch.Tensor] | None]:
    """(policy tensors, critic tensors or None where the folder has none) to begin training from."""
    folder = Path(folder)
    critic = folder / store.CRITIC_FILE
    return store.load_tensors(folder / store.POLICY_FILE), store.load_tensors(critic) if critic.exists() else None


def passed_over(keyboard: KeyboardSpec, hand: HandSpec) -> str:
    """Why the packaged general policies do not play a piece read for ``keyboard`` and ``hand``, in
    words naming the settings (the first that differs); '' where one plays it."""
    packaged = general_candidates(None)
    if not packaged or any(
        plays_keyboard(env, sac, keyboard) and env.world.hand.spec == hand
        for env, sac in (policy_configs(f) for f in packaged)
    ):
        return ""
    world = policy_configs(packaged[0])[0].world
    hands = list(dict.fromkeys(policy_configs(f)[0].world.hand.spec for f in packaged))
    if hand not in hands:
        return (
            f"the packaged general policies play with fingers {' or '.join(h.describe() for h in hands)}; this "
            f"piece is read for fingers {hand.describe()} (hand.fingers, hand.model)"
        )
    return (
        f"the packaged general policies play keyboards of {world.keyboard.spec.count} keys or more; this piece is "
        f"read for {keyboard.describe()} (keyboard.count)"
    )


def piece_hand_models(root: Path, piece: str | None) -> set[str]:
    """The hand models (``HandSpec.model``) of the phrase policies in the store ``root`` trained for
    the file named ``piece`` (its manifests' ``piece``: the file's name, a two-hand file's parts as
    '<name> (right hand)'; a phrase two files share is recorded for the first one trained), or,
    ``piece`` None, of the store's general policies for hands' parts (``task-parts*``); empty where
    there are none. A manifest that cannot be read is passed over."""
    found = set()
    for folder in Path(root).iterdir() if Path(root).is_dir() else ():
        general = folder.name.startswith("task-")
        wanted = folder.name.startswith("task-parts") if piece is None else not general
        if not wanted or not store.is_trained(folder):
            continue
        try:
            manifest = store.read_manifest(folder)
        except PianobotError:
            continue
        named = manifest.get("piece")
        if piece is None or (isinstance(named, str) and (named == piece or named.startswith(f"{piece} ("))):
            spec = manifest["config"]["env"].get("world", {}).get("hand", {}).get("spec", {})
            found.add(spec.get("model", "allegro") if isinstance(spec, dict) else "allegro")
    return found
