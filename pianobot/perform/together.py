"""Both hands of a piece, played in one simulation (or each hand in a simulation of its own).

Each hand's part is given to a player that knows one right hand (the scripted pianist, the
general policy, phrase policies), in two steps that keep every key's colour and every distance
between keys:

1. the left hand's part is mirrored about D (:meth:`~pianobot.music.piece.Piece.mirror`): the
   mirror image of a left hand is a right hand with the same finger numbers;
2. the part is moved by whole octaves onto the keyboard its player knows (:class:`Window`): the
   general policy's 24 keys, or, for the scripted pianist and for a part wider than 24 keys, the
   part's own range rounded out to octaves (the general policies play any keyboard of at least
   their own keys: :func:`~pianobot.agent.general.plays_keyboard`).

Notes outside the window (only where ``--lowest-note``/``--keys`` name the keys) are left out, and the part is then reduced to what the hand can play
(:func:`~pianobot.pianist.reduce.reduce_part`), each kind of change said in one warning line; the
figures are always against the piece as written, so what was left out counts as missed.

By default both hands then play in one simulation (:class:`~pianobot.env.two_hands.HandsEnv`): two
hands on one keyboard of the keys both windows need, each player seeing its hand through its
window, the hands kept apart by the world (the right wrist at least a hand's thumb reach above
the left; their links collide), a key struck by one sounding for both. Where that cannot be
(the windows span more than 88 keys, or the two hands' players were trained with different
physics) each hand plays in a simulation of its own, said in one warning line, and what the
two keyboards sounded is merged.

Reading a file (whether it plays both hands, each hand's part, with which fingers) is
:mod:`pianobot.pianist.reading`'s; :func:`play` (``pianobot.play``) plays a piece with both
hands with :func:`play_hands` and any other piece as one hand.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable

from pianobot.agent.general import parts_policy
from pianobot.errors import PianobotError, PianobotWarning, SettingError
from pianobot.music.instrument import THUMB, HandSpec, KeyboardSpec
from pianobot.music.metrics import Report, compare
from pianobot.music.pedal import Pedal
from pianobot.music.per_hand import HandsReport, compare_hands
from pianobot.music.piece import FINGER_NAMES, HANDS, Piece
from pianobot.music.window import Window
from pianobot.perform import compose, plan
from pianobot.perform.judge import play_one_hand
from pianobot.perform.plan import Performance
from pianobot.perform.rollout import Rollout
from pianobot.pianist.assign import finger_apart
from pianobot.pianist.parts import prepare_part, thumbs_keep_more
from pianobot.pianist.reading import (  # noqa: F401 (the reading, pianist/reading.py's: these names kept here too)
    THUMBS_CHOSEN,
    HandsReading,
    _warn_again,
    fingers_for_file,
    names_hands,
    one_hand_refusal,
    read_hands,
    two_hands,
)
from pianobot.sim.hand import hand_model

APART = "each hand in a simulation of its own"
"""How both hands play with ``together=False``: said wherever such a performance is reported."""
TOGETHER = "both hands in one simulation"
"""How both hands play by default (:class:`~pianobot.env.two_hands.HandsEnv`)."""
AGAINST = "figures against the piece as read from the file (notes left out or reduced for a hand count as missed)"
"""What the figures of both hands are against: the file's notes, but for a chord of more notes than both
hands have fingers, thinned as the file is read (said in its own line)."""
"""What a two-hand performance's figures are measured against."""


@dataclass(frozen=True)
class HandPerformance:
    """One hand's part as its simulation played it."""

    hand: str
    window: Window
    part: Piece
    """What the simulated hand was given: mirrored, moved, reduced and fingered, starting at ``start``."""
    start: float
    """Seconds by which the part was moved earlier (its first onset in the piece)."""
    left_out: int
    """Written notes outside the window."""
    performance: Performance
    changes: tuple[str, ...] = ()
    """What was left out or reduced to make the part playable: one line per kind."""
    sounded: Piece | None = None
    """Played with the other hand in one simulation: what this hand sounded, at the written
    pitches and times (else :attr:`played` is read from its own simulation)."""

    @property
    def played(self) -> Piece:
        """What this hand sounded, back at the written pitches and times, each note with its hand."""
        return self.sounded if self.sounded is not None else self._written(self.performance.played)

    @property
    def given(self) -> Piece:
        """What this hand was given to play (:attr:`part`), back at the written pitches and times, each
        note with its hand: the notes and lengths a player who plays every one of them as given sounds."""
        return self._written(self.part)

    def _written(self, piece: Piece) -> Piece:
        """``piece``, in the simulated hand's keys and times, back at the written ones, each note with its hand."""
        notes = [replace(n, pitch=self.window.outward(n.pitch), hand=self.hand) for n in piece.shift(self.start).notes]
        return Piece(tuple(notes), bpm=self.part.bpm)

    @property
    def performer(self) -> str:
        """Who played this hand, in words ('scripted pianist', 'general policy task-parts-... through the
        hold guard', ...): the two hands may have different general policies."""
        played = self.performance.plan
        folders = dict.fromkeys(s.policy.name for s in played.stretches if s.player is plan.Player.GENERAL)
        guarded = ["through the hold guard"] if self.performance.held_steps is not None else []
        return " ".join([played.performer, *folders, *guarded])

    def describe(self) -> str:
        """Where and with what the simulated hand played the part, in the piece's own keys: 'on C4-B5
        (24 keys)', the left hand's 'mirrored about D, on F2-E4 (24 keys)' (its player is a right hand,
        its part the mirror image), ", its player's keys 1 octave up" where the part was moved onto
        its player's keys, and ', with its thumb' where the Allegro-like hand had one (another hand model:
        ', the pianist hand')."""
        where = ["mirrored about D"] if self.hand == "left" else []
        where.append(f"on {self.window.written_keys().describe()}")
        if self.window.moved():
            where.append(self.window.moved())
        spec = self.performance.plan.config.world.hand.spec
        thumb = [f"with its {FINGER_NAMES[1]}"] if 1 in spec.fingers else []
        return ", ".join(where + (thumb if spec.model == "allegro" else [f"the {spec.model} hand"]))


@dataclass(frozen=True)
class HandsPerformance:
    """A two-hand piece performed (the module's notes)."""

    piece: Piece
    """The piece as written, every note with its hand: what the figures are against."""
    hands: tuple[HandPerformance, ...]
    """Right hand first."""
    seed: int = 0
    together: bool = False
    """Both hands in one simulation (else each in a simulation of its own)."""
    frames: list | None = field(default=None, repr=False, compare=False)
    """With a video asked for: the simulation's rendered frames, the first before the first step."""
    start: float = 0.0
    """Simulated time (s), from the first frame, at which the piece's time 0 falls (less than 0
    when the piece begins with a rest longer than the lead-in): where the video's sound starts."""
    pedal: Pedal = Pedal()
    """The sustain pedal as the foot worked it, in the piece's time."""
    written_pedal: Pedal = Pedal()
    """The piece's own sustain pedal."""
    played: Piece = field(init=False)
    """What both keyboards sounded, as one piece at the written pitches, each note with its hand."""
    scores: HandsReport = field(init=False, repr=False, compare=False)
    """The figures for the whole piece and each hand (:func:`~pianobot.music.per_hand.compare_hands`)."""

    def __post_init__(self) -> None:
        played = Piece(tuple(n for h in self.hands for n in h.played.notes), self.piece.bpm)
        object.__setattr__(self, "played", played)
        object.__setattr__(self, "scores", compare_hands(self.piece, played, pedals=(self.written_pedal, self.pedal)))

    def report(self, hand: str | None = None) -> Report:
        """The figures for the whole piece, or for ``hand``'s part (against its written notes),
        as ``pianobot score`` computes them from the written file."""
        return self.scores.whole if hand is None else self.scores.hands[hand]

    def given_report(self) -> Report:
        """The figures of both hands' :attr:`~HandPerformance.given` notes against the piece as written:
        what a player who plays every given note as given would score, the most the reduction leaves."""
        given = Piece(tuple(n for h in self.hands for n in h.given.notes), self.piece.bpm)
        return compare(self.piece, given)

    @property
    def performer(self) -> str:
        """Who played, in words: 'scripted pianist (both hands in one simulation)'."""
        names = dict.fromkeys(h.performer for h in self.hands)
        return f"{' and '.join(names)} ({self.simulated})"

    @property
    def fps(self) -> float:
        """Frames per second of :attr:`frames`: the control rate."""
        return self.hands[0].performance.plan.config.world.control_hz

    @property
    def simulated(self) -> str:
        """How the hands were simulated, in words: :data:`TOGETHER` or :data:`APART`."""
        return TOGETHER if self.together else APART

    def to_dict(self, reading: HandsReading | None = None) -> dict:
        """The report's JSON: who played each hand, where, what was left out or reduced, and the
        figures for the whole piece and each hand (``reading``: what the file named)."""
        hands = {}
        for h in self.hands:
            hands[h.hand] = {
                "performer": h.performer,
                **(reading.to_dict(h.hand) if reading is not None else {}),
                "played_as": h.describe(),
                "hand_model": h.performance.plan.config.world.hand.spec.model,
                "fingers": list(h.performance.plan.config.world.hand.spec.fingers),
                "given_to_the_hand": len(h.part),
                "left_out_or_reduced": list(h.changes),
                "plan": h.performance.plan.to_dict(),
                **h.performance.guards(),
                **self.report(h.hand).summary(),
            }
        whole = self.report().to_dict()
        for note, row in zip(whole["notes"], self.report().rows):  # each note with the hand that has it
            note["hand"] = (row.reference or row.played).hand
        return {
            "seed": self.seed,
            "performer": self.performer,
            "hands_simulated": f"{self.simulated}; {AGAINST}"
            if self.together
            else f"apart: {APART}, the two merged; {AGAINST}",
            "hands": hands,
            **whole,
        }


def play_hands(
    piece: Piece,
    controller: str = "sac",
    models: Path | str | None = None,
    seed: int = 0,
    hand: HandSpec | None = None,
    keyboard: KeyboardSpec | None = None,
    together: bool = True,
    on_step: Callable[[int, int], None] | None = None,
    video: bool = False,
    pedal: Pedal = Pedal(),
    **options,
) -> HandsPerformance:
    """Perform ``piece``, every note of which has a hand (the module's notes), with its sustain
    ``pedal`` (the foot plays it as written): ``controller``
    'sac' (the general policy, or policies trained for the part) or 'scripted', ``models`` the
    model store, ``seed`` the hand starts, ``hand`` each hand's fingers (default: three, or with
    the thumb too where that keeps more of the notes, :func:`thumbs_keep_more`, said in one
    warning line); ``keyboard`` the keys
    every part is moved onto (default: for 'sac' the general policy's 24 keys, or a part's own
    range, rounded out to octaves, where it is wider; for 'scripted' each part's own range);
    ``together``: both hands in one simulation (else hand by hand, each in
    a simulation of its own); ``on_step(done, total)`` reports progress; ``video``: keep the
    frames (both hands in one simulation only); ``options`` go to
    :func:`~pianobot.perform.plan.plan_performance` (``general``, ``fallback``, ...), where
    ``general_policy`` may also be a dict by hand (``{"left": folder}``: one policy per hand)."""
    if any(n.hand is None for n in piece.notes):
        raise PianobotError("every note needs a hand to play both hands: give the piece's notes a hand first")
    if controller not in ("sac", "scripted"):
        raise PianobotError(f"controller {controller!r}: both hands are played by 'sac' or 'scripted'")
    fingers = hand
    if hand is None:
        counts = thumbs_keep_more(piece, keyboard=keyboard)
        fingers = HandSpec() if counts is None else THUMB
        if counts is not None:
            said = THUMBS_CHOSEN.format(more=counts[1], given=counts[0])
            warnings.warn(PianobotWarning(f"{said} (hand=HandSpec() plays with three)"))
    grow = keyboard is None and controller == "sac"  # (the policies' 24 keys, or a wider part's own)
    keyboard = keyboard or (KeyboardSpec() if controller == "sac" else None)
    together = together and len(piece.hands) == 2
    parts = prepare_parts(piece, keyboard, fingers, together, grow)
    plans = plan_hands(parts, controller, models, fingers, options)
    return perform_hands(piece, parts, plans, seed, together, on_step, video, pedal)


def prepare_parts(
    piece: Piece, keyboard: KeyboardSpec | None, fingers: HandSpec, together: bool = True, grow: bool = False
) -> dict[str, tuple]:
    """Each hand's part as :func:`play_hands` gives it to its player, by hand (right first):
    (window, part, start, notes left out, changes), :func:`prepare_part`'s with the lines it
    warned (each said once more here). ``together``: both parts on one timeline, from the
    piece's first note (else each from its own); ``grow``: as :func:`prepare_part`'s."""
    offset = piece.notes[0].onset if together else None
    fingered = sum(n.finger is not None for n in piece.notes)
    written = hand_model(fingers.model).written_fingering  # (the file's marks kept: prepare_part)
    if fingered and not written:
        warnings.warn(
            PianobotWarning(
                f"the piece's fingering ({fingered} of {len(piece)} notes) is not used with both hands: the fingering "
                "planner fingers each hand's part for the robot's fingers, the hands kept apart (play one hand as "
                "fingered with load.hand right or load.hand left)"
            )
        )
    parts = {}
    for name in (h for h in HANDS if h in piece.hands):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", PianobotWarning)
            prepared = prepare_part(piece, name, keyboard, fingers, offset, grow)
        changes = tuple(str(w.message) for w in caught if issubclass(w.category, PianobotWarning))
        _warn_again(caught)
        parts[name] = (*prepared, changes)
    if together and len(parts) == 2:  # fingerings that keep the wrists apart, where they can
        marked = tuple(h for h in parts if written and any(n.finger is not None for n in piece.part(h).notes))
        apart = finger_apart({h: (window, part) for h, (window, part, *_) in parts.items()}, fingers, marked)
        parts = {h: (window, apart[h].piece if apart[h] else part, *rest) for h, (window, part, *rest) in parts.items()}
    return parts


def hand_players(parts: dict[str, tuple], controller: str, models, fingers: HandSpec, options: dict) -> dict[str, dict]:
    """Each hand's options for its plan (:func:`~pianobot.perform.plan.plan_performance`): those
    given (``general_policy`` may be a dict by hand), and, for 'sac', the packaged parts policy on
    every hand no general policy was named for. (Through the hold guard it plays the right hands of
    two-hand pieces better than the melody policy does: docs/benchmarks.md, "Two hands".)"""
    given = {name: _hand_options(options, name) for name in parts}
    if controller != "sac":
        return given
    return {name: _parts_default(given[name], models, window.keyboard, fingers) for name, (window, *_) in parts.items()}


def plan_hands(
    parts: dict[str, tuple], controller: str, models, fingers: HandSpec, options: dict
) -> dict[str, plan.PerformancePlan]:
    """Each hand's plan for its part, with :func:`hand_players`' options; where the packaged parts
    policy does not fit the phrase policies in ``models``, as if it had not been offered (so the
    general policy is)."""
    given = {name: _hand_options(options, name) for name in parts}
    by_hand = hand_players(parts, controller, models, fingers, options)
    plans = {}
    for name, (window, part, *_) in parts.items():
        try:
            plans[name] = plan.plan_performance(
                part, controller, models, keyboard=window.keyboard, hand=fingers, **by_hand[name]
            )
        except SettingError:
            if by_hand[name] == given[name]:  # (nothing was offered: the error is the given options')
                raise
            plans[name] = plan.plan_performance(
                part, controller, models, keyboard=window.keyboard, hand=fingers, **given[name]
            )
    return plans


def perform_hands(
    piece: Piece,
    parts: dict[str, tuple],
    plans: dict[str, plan.PerformancePlan],
    seed: int = 0,
    together: bool = True,
    on_step: Callable[[int, int], None] | None = None,
    video: bool = False,
    pedal: Pedal = Pedal(),
) -> HandsPerformance:
    """Play each hand's plan from hand start ``seed``, the foot playing ``pedal`` as written: both in
    one simulation where ``together`` allows it (else, said in one warning line, each in a
    simulation of its own, the pedal with each)."""
    together = together and len(parts) == 2
    if together:
        try:
            return _play_together(piece, parts, plans, seed, on_step, video, pedal)
        except HandsApart as e:
            if video:
                raise PianobotError(f"{e}: no video can show both hands; play one hand for it") from None
            warnings.warn(PianobotWarning(f"{e}: each hand plays in a simulation of its own"))
    elif video:
        raise PianobotError("a video of both hands needs them in one simulation: play one hand for it")
    done = []
    for name, (window, part, start, left_out, changes) in parts.items():
        own = replace(plans[name], pedal=pedal.shift(-start))
        performance = plan.perform_plan(own, seed, on_step=on_step)
        done.append(HandPerformance(name, window, part, start, left_out, performance, changes))
    first = done[0]  # (each hand's foot played the same pedal: the first's is written)
    played = first.performance.rollout.pedal.shift(first.start)
    return HandsPerformance(piece, tuple(done), seed, pedal=played, written_pedal=pedal)


def _hand_options(options: dict, hand: str) -> dict:
    """``options`` for ``hand``'s plan: a ``general_policy`` given by hand (``{"right": ..., "left":
    ...}``) becomes that hand's (a hand it leaves out gets the default)."""
    policy = options.get("general_policy")
    if not isinstance(policy, dict):
        return options
    unknown = set(policy) - set(HANDS)
    if unknown:
        raise PianobotError(
            f"general policies by hand: {', '.join(sorted(unknown))} is not a hand; give right and/or left"
        )
    return {**options, "general_policy": policy.get(hand)}


def _parts_default(options: dict, models, keyboard: KeyboardSpec, fingers: HandSpec) -> dict:
    """A hand's options with the packaged parts policy (:func:`~pianobot.agent.general.parts_policy`:
    each hand's of a two-hand piece) where none was named for it (``general_policy`` for both
    hands, or by hand) and the general policy may play."""
    if not options.get("general", True) or options.get("general_policy") is not None:
        return options
    policy = parts_policy(Path(models) if models is not None else plan.DEFAULT_MODELS, keyboard, fingers)
    return options if policy is None else {**options, "general_policy": policy}


class HandsApart(Exception):
    """Why both hands cannot play in one simulation."""


def _play_together(
    piece: Piece,
    parts: dict,
    plans: dict[str, plan.PerformancePlan],
    seed: int,
    on_step: Callable | None,
    video: bool,
    pedal: Pedal,
) -> HandsPerformance:
    """Both hands' plans played in one :class:`~pianobot.env.two_hands.HandsEnv` from hand start
    ``seed``, the foot playing ``pedal``."""
    offset = parts["right"][2]  # (the piece's first onset: both parts start from it)
    from pianobot.env.two_hands import HandsEnv  # (the simulator loads only when something plays)
    from pianobot.sim.recorder import NoteRecorder

    try:
        env = HandsEnv(
            {h: (parts[h][0], parts[h][1]) for h in HANDS},
            {h: plans[h].config for h in HANDS},
            render_mode="rgb_array" if video else None,
            pedal=pedal.shift(-offset),
        )
    except ValueError as e:  # parts too far apart for 88 keys, players of different physics
        raise HandsApart(str(e)) from None
    try:
        controllers = {h: plan.controller_for(plans[h], env.hands[h], seed) for h in HANDS}
        observations, _ = env.reset(seed=seed)
        for c in controllers.values():
            c.reset()
        recorder, rewards, steps = NoteRecorder(), dict.fromkeys(HANDS, 0.0), 0
        frames = [env.render()] if video else None
        while True:
            now = env.world.time
            observations, _, _, truncated, info = env.step({h: c.act(observations[h]) for h, c in controllers.items()})
            recorder.press(now, info["pedal"])
            if frames is not None:
                frames.append(env.render())
            recorder.add(info["events"], info["fingers"], info["struck_by"])
            for h in HANDS:
                rewards[h] += info["rewards"][h]
            steps += 1
            if on_step is not None:
                on_step(steps, env.horizon)
            if truncated:
                break
        sounded = recorder.piece(end=env.world.time, start=env.score_start, bpm=piece.bpm).shift(offset)
        footed = recorder.pedal(end=env.world.time, start=env.score_start).shift(offset)
    finally:
        env.close()
    done = []
    for h in HANDS:
        window, part, start, left_out, changes = parts[h]
        own = Piece(tuple(n for n in sounded.notes if n.hand == h), bpm=piece.bpm)
        moved = [
            replace(n, pitch=window.inward(n.pitch))
            for n in own.shift(-start).notes
            if 0 <= window.inward(n.pitch) <= 127
        ]
        inward = Piece(tuple(moved), bpm=piece.bpm)  # (what the hand's player saw itself play)
        rollout = Rollout(part, inward, rewards[h], steps, None, env.score_start)
        performance = Performance(
            plans[h],
            rollout,
            seed,
            compose.slowed_steps(controllers[h]),
            compose.held_steps(controllers[h]),
            compose.wrist_steps(controllers[h]),
        )
        done.append(HandPerformance(h, window, part, start, left_out, performance, changes, own))
    start = env.score_start - offset
    return HandsPerformance(
        piece, tuple(done), seed, together=True, frames=frames, start=start, pedal=footed, written_pedal=pedal
    )


def play(
    piece: Piece, controller: str = "sac", models: Path | str | None = None, seed: int = 0, **options
) -> Performance | HandsPerformance:
    """``pianobot.play``: a piece with both hands (every note with its hand, both hands with notes)
    plays both, :func:`play_hands` (``options`` as there);
    any other piece plays as one hand, :func:`pianobot.perform.judge.play_one_hand` (``options`` as there:
    ``video``, ``on_step``, ``keyboard``, ``hand``, ``general``, ...)."""
    if len(piece.hands) < 2:
        return play_one_hand(piece, controller, models, seed, **options)
    return play_hands(piece, controller, models, seed, **options)
