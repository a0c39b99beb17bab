"""A trained policy of the finger-shared actor given a hand with more fingers (the thumb).

The 'fingers' actor (:class:`~pianobot.agent.actors.FingerActor`) moves every finger with one
network, which reads the finger's own joints, joint speeds and target, its one-hot index and the
whole observation vector; the wrist's network reads the vector. Nothing in either is sized for
one finger, so a policy trained for fingers 2-4 can start a hand with fingers 1-4 (``python -m
pianobot.agent.widen SOURCE DESTINATION --fingers 1,2,3,4``): every trained weight is kept, the
fingers it knew read and act as before, and each input the new hand adds gets weights that
change nothing the policy did (the new finger's joints, speeds and target in the vector: zero)
or that make the new finger one like the others (its index: the mean of the known fingers'
index weights). The new finger then moves as the network moves any finger towards its target:
the fingering planner gives it notes (a thumb takes the lowest), and training on from the
widened policy (``pianobot train --task parts --thumb --general-policy DESTINATION``) teaches the
rest. The critic's encoder, which the actor does not read (DAgger learns no critic), is a fresh
one for the new hand.

``--hand-model pianist`` gives the weights to another body with the same joints per finger (the
pianist's five fingers, from the Allegro-like hand's three): nothing there is as the policy
learnt it (other finger lengths, joint ranges and palm), so it is only a start for training on
that hand (``pianobot train --task melody --hand-model pianist --general-policy DESTINATION``).
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np
import torch

from pianobot.agent import store
from pianobot.agent.actors import FingerLayout, finger_layout
from pianobot.agent.policy import make_agent, policy_configs, policy_target
from pianobot.agent.tasks import make_env
from pianobot.config import to_dict
from pianobot.errors import PianobotError
from pianobot.music.instrument import HandSpec
from pianobot.sim.hand import HAND_MODELS, hand_config, hand_model

WIDENED = "widened"
"""A widened policy's manifest says ``"kept": "widened"``: it was not trained as it is."""


def context_sources(old: FingerLayout, new: FingerLayout, slots: list[int], rest: int) -> np.ndarray:
    """For each value of the new hand's observation vector (after the score window), the index of
    the same value in the old hand's, or -1 for a value the old hand had none of (a new finger's):
    the wrist (2), then joints, joint speeds and targets finger by finger, then ``rest`` more
    (the keys', where observed). ``slots[i]`` is the new slot of the old hand's finger ``i``."""
    if old.joints != new.joints or old.target_width != new.target_width:
        raise PianobotError(
            "the policy's fingers and the new hand's observe different joints or targets: widen a policy only "
            "to a hand whose fingers have the same joints"
        )
    sources = [0, 1]
    old_base, new_base = 2, 2
    for width in (old.joints, old.joints, old.target_width):
        for slot in range(new.fingers):
            if slot in slots:
                start = old_base + slots.index(slot) * width
                sources.extend(range(start, start + width))
            else:
                sources.extend([-1] * width)
        old_base += old.fingers * width
        new_base += new.fingers * width
    sources.extend(range(old_base, old_base + rest))
    return np.array(sources)


def _columns(weight: torch.Tensor, sources: np.ndarray) -> torch.Tensor:
    """``weight``'s input columns rearranged by ``sources`` (-1: a zero column)."""
    out = torch.zeros(weight.shape[0], len(sources), dtype=weight.dtype)
    known = sources >= 0
    out[:, torch.from_numpy(np.flatnonzero(known))] = weight[:, torch.from_numpy(sources[known])]
    return out


def widen_actor(
    tensors: dict[str, torch.Tensor], old: FingerLayout, new: FingerLayout, slots: list[int], rest: int
) -> dict[str, torch.Tensor]:
    """The 'fingers' actor's tensors (``actor.*``, as :meth:`~pianobot.agent.sac.SAC.tensors`
    names them) for the new hand: the first layers' input columns as :func:`context_sources`
    says, a new finger's index column the mean of the others'; every other tensor as it is."""
    context = context_sources(old, new, slots, rest)
    own_before = 2 + 2 * old.joints + old.target_width  # the finger's own values, before its index
    index = np.array([slots.index(s) if s in slots else -1 for s in range(new.fingers)])
    out = dict(tensors)
    first = tensors["actor.finger.0.weight"]
    old_context = 2 + old.fingers * (2 * old.joints + old.target_width) + rest
    if first.shape[1] != own_before + old.fingers + old_context:
        raise PianobotError(
            f"the policy's actor.finger.0.weight reads {first.shape[1]} values where its manifest's environment "
            f"gives {own_before + old.fingers + old_context}: the folder's files do not belong together"
        )
    own = first[:, :own_before]
    onehot = first[:, own_before : own_before + old.fingers]
    new_onehot = _columns(onehot, index)
    new_onehot[:, index < 0] = onehot.mean(dim=1, keepdim=True)
    vector = _columns(first[:, own_before + old.fingers :], context)
    out["actor.finger.0.weight"] = torch.cat([own, new_onehot, vector], dim=1).contiguous()
    out["actor.wrist.0.weight"] = _columns(tensors["actor.wrist.0.weight"], context).contiguous()
    return out


def widen_policy(source: Path, destination: Path, fingers: tuple[int, ...], model: str | None = None) -> Path:
    """A policy folder at ``destination`` holding ``source``'s 'fingers' actor widened to a hand
    with ``fingers`` (a superset of its own), of hand model ``model`` (None: the policy's own; another
    model's body gets the same weights, a start for training on it), and a manifest that says so
    (``"kept": "widened"``, no training of its own). Returns ``destination``."""
    env, sac = policy_configs(source)
    if sac.actor != "fingers" or sac.score_input:
        raise PianobotError(
            f"{source} has the {sac.actor!r} actor{' reading the score window' if sac.score_input else ''}: only "
            "the 'fingers' actor without it (train.sac.actor fingers) reads every finger alike"
        )
    before = env.world.hand.spec.fingers
    model = hand_model(model or env.world.hand.spec.model)
    if not set(fingers) <= set(model.fingers):
        raise PianobotError(
            f"fingers {','.join(map(str, fingers))}: the {model.name} hand has fingers {','.join(map(str, model.fingers))}"
        )
    same_body = model.name == env.world.hand.spec.model
    if not (set(before) < set(fingers) if same_body else set(before) <= set(fingers)):
        raise PianobotError(
            f"fingers {','.join(map(str, fingers))} do not add to the policy's own ({','.join(map(str, before))}): "
            "name all of them, e.g. --fingers 1,2,3,4"
        )
    if (destination / store.MANIFEST_FILE).exists():
        raise PianobotError(f"{destination} already holds a policy: name a new folder")
    spec = HandSpec(tuple(sorted(fingers)), model=model.name)
    hand = replace(env.world.hand, spec=spec) if same_body else hand_config(spec)
    wide = replace(env, world=replace(env.world, hand=hand))
    target = policy_target(source)
    layouts, rests = [], []
    for config in (env, wide):
        instance = make_env(target, config)
        try:
            space = instance.observation_space
            layouts.append(finger_layout(space))
            rests.append(sum(int(np.prod(space[k].shape)) for k in ("keys", "key_velocities") if k in space.spaces))
            if config is wide:
                torch.manual_seed(0)  # (the fresh encoder: the same file every time)
                fresh = make_agent(instance, sac).tensors(with_training_state=False)
        finally:
            instance.close()
    if rests[0] != rests[1]:
        raise PianobotError("the new hand observes the keys differently from the policy: widen on the same keyboard")
    old_tensors = store.load_tensors(source / store.POLICY_FILE)
    slots = [sorted(fingers).index(f) for f in before]
    actor = widen_actor({k: v for k, v in old_tensors.items() if k.startswith("actor.")}, *layouts, slots, rests[0])
    tensors = {**{k: v for k, v in fresh.items() if k.startswith("encoder.")}, **actor}
    manifest = store.read_manifest(source)
    manifest.update(
        steps=0,
        updates=0,
        seconds=0.0,
        start={"path": str(source), "sha256": store.file_digest(source / store.POLICY_FILE), "critic": False},
        kept=WIDENED,
        evaluation=None,
        evaluations=[],
        widened={
            "fingers_before": list(before),
            "fingers": sorted(fingers),
            "hand_model_before": env.world.hand.spec.model,
            "hand_model": model.name,
        },
    )
    manifest["config"]["env"] = to_dict(wide)
    for field in ("format", "saved", "versions"):  # (save_policy writes them anew)
        manifest.pop(field, None)
    store.save_policy(destination, tensors, manifest)
    return destination


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("source", type=Path, help="a trained policy folder of the 'fingers' actor")
    parser.add_argument("destination", type=Path, help="a new folder for the widened policy")
    parser.add_argument(
        "--fingers", help="the new hand's fingers (default: 1,2,3,4, or with --hand-model that model's default fingers)"
    )
    parser.add_argument(
        "--hand-model", choices=tuple(HAND_MODELS), help="the new hand's model (default: the policy's own)"
    )
    args = parser.parse_args(argv)
    torch.set_num_threads(1)
    if args.fingers is None:
        args.fingers = (
            "1,2,3,4" if args.hand_model is None else ",".join(map(str, hand_model(args.hand_model).finger_sets[0]))
        )
    try:
        fingers = tuple(int(f) for f in args.fingers.split(","))
    except ValueError:
        parser.error(f"--fingers {args.fingers}: give finger numbers separated by commas, e.g. 1,2,3,4")
    try:
        print(widen_policy(args.source, args.destination, fingers, args.hand_model))
    except PianobotError as e:
        parser.error(str(e))


if __name__ == "__main__":
    main()
