"""The scripted pianist's tuning constants, in one place, each with its unit.

Lengths are in metres (m), angles in radians (rad), times in control steps (50 ms at the
default 20 Hz). Heights are measured from a fingertip's lowest point to a key's top surface.
They were tuned by hand on the examples and the task families (tests/test_controllers.py), for
the Allegro-like hand; a hand model sets its own where it differs
(:attr:`~pianobot.sim.hand.HandModel.tuning`, applied by :func:`tuning_for`; the pianist's
hand's are in docs/simulator.md). :mod:`~pianobot.pianist.strikes` reads the strike constants
and :mod:`~pianobot.pianist.motion` the positioning ones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from pianobot.sim.hand import HandConfig


@dataclass(frozen=True)
class PianistTuning:
    """How the scripted pianist moves: hover heights, tolerances, margins and speed limits."""

    # -- strikes (pianobot/pianist/strikes.py) ---------------------------------------------------
    min_ready_height: float = 0.003
    """Lowest hover height over the key's top before a strike (m)."""
    strike_margin: float = 0.001
    """The fingertip is planned to pass the strike depth by up to this much at the onset (m)."""
    hold_depth_margin: float = 0.0025
    """A struck key is pressed this far past its strike depth before the finger just holds it (m).
    It also bounds when in the onset's step a loud strike sounds: the fingertip must not reach
    the key's bottom within that step, or the step's speed, and the note, would be softer."""
    max_strike_speed: float = math.inf
    """Fastest downward fingertip speed a strike is planned at (m/s): a louder note is struck at this
    speed, softer than written but on time, where the hand's fingers are too slow to strike it as
    written (none: the Allegro-like hand's strike any velocity)."""
    min_lead_steps: int = 0
    """Fewest control steps of constant-speed travel before the onset's step (0: a loud strike starts
    from rest at the onset step's start; the finger's motors reach the strike speed within a few
    milliseconds, and its ready height is one step's travel lower)."""
    prepare_steps: int = 4
    """Least time a finger needs to lift, move over and settle before a strike from the ready height (control steps)."""
    settle_steps: int = 1
    """Time a fingertip that has reached its ready height needs to be still and in front of its key
    before its strike starts (control steps). A held key is let go in time for the path there
    (at ``max_move`` per step), this and the strike."""
    hold_reach: float = 0.030
    """Farthest the wrist may be from straight over a held key: the abduction makes up for it (m)."""
    lift_steps: int = 1
    """Time a finger that lets go of its key needs to rise clear of the keys before the wrist slides
    (control steps): a holding finger lets go this much earlier for a strike of its own that needs
    the wrist elsewhere."""
    strike_reach: float = 0.030
    """Farthest the wrist may be from straight over a white key that a finger strikes while other
    fingers hold theirs: the abduction makes up for it, and the held keys are not let go (m)."""
    black_strike_reach: float = 0.018
    """The same for a black key: a slanted fingertip slips off its narrow top sooner (m)."""
    lone_strike_wrist_steps: int = 0
    """Control steps a strike alone at its onset (no other finger's strike then) may begin before the
    wrist, sliding at ``hold_slide`` while fingers hold keys, has come where it keeps the held keys and
    lets the striking finger reach its key: the held keys are let go that much later for it, and the
    wrist slides on into place as the finger goes down (0, the default, the Allegro-like hand's: it is
    there when the strike begins)."""
    repeat_prepare_steps: int = 1
    """Least time a finger needs to let its key rise and be still over it again, before it strikes the
    same key again from the ready height (control steps): no move across, so less than ``prepare_steps``."""

    # -- fingering (pianobot/pianist/fingering.py) ---------------------------------------------------
    reach_fraction: float = 0.75
    """Share of what a finger's abduction limit reaches sideways that the fingering planner uses (the
    rest is margin for aim)."""
    settle_time: float = 0.2
    """Seconds the fingering planner leaves around every wrist move for the fingers to lift and
    settle (the Allegro-like hand's: the scripted pianist's ``prepare_steps``); the reduction drops
    what the wrist cannot reach in the time left."""
    thumb_stretch: float = 1.0
    """Share of the fingering planner's stretch cost the thumb pays (1: as much as any finger). A
    pianist's thumb turns under the palm with ease: less, and the planner fingers a scale with the
    thumb under (1 2 3 1) rather than the whole hand shifting after the fifth finger."""
    legato_cost: float = 2.0
    """The fingering planner's cost of a note let go before its written end, per share of its written
    length lost (in white keys of wrist travel: a whole note lost costs as much as a move of this many)."""

    # -- motion (pianobot/pianist/motion.py) -----------------------------------------------------
    idle_height: float = 0.010
    """Fingertip height over its key's top (or the white keys' top) when it has nothing to do (m)."""
    aim_tolerance: float = 0.004
    """A finger waits at idle height until its tip is this close to above its key (m)."""
    path_tolerance: float = 0.002
    """A fingertip that must rise more than this rises first; one that must move across more than this moves across before it goes down (m)."""
    clearance: float = 0.003
    """The hand does not slide while a finger that has let go is lower than this over the white keys (m)."""
    band_clearance: float = 0.004
    """Crossing into or out of the black keys' band, the fingertip stays this far above their tops (m)."""
    band_tolerance: float = 0.0002
    """A fingertip this little under the safe height for crossing counts as over it (m).
    One that rose towards it could stop a hair short of it and wait there for ever."""
    max_move: float = 0.016
    """Longest fingertip move in one step when positioning; strikes are not limited (m per control step)."""
    travel_share: float = 1.0
    """Share of ``max_move`` a fingertip is counted on to cover in a control step when the strike planner
    times its way to its next key: when a held key is let go for it, and so how soon the fingering
    planner lets a finger strike again (and the reduction drops notes as too fast). Less than 1 where
    the fingertip is slower than its waypoints (it rises first, draws back out of the black keys' band
    and turns while the wrist moves)."""
    max_joint_move: float = 0.6
    """Largest change of a flexion joint's angle in one step when positioning (rad per control step)."""
    hold_slide: float = 0.008
    """Farthest the wrist may move in one step while a finger holds a key (m per control step)."""
    strike_slide: float = math.inf
    """Farthest the wrist may move in one step while a striking fingertip is low, on its way into its
    key (m per control step; ``math.inf``, the default: no limit, the finger following the wrist
    with its abduction). Fingers about to strike, not yet down, never limit it."""
    tilt_step: float = 0.15
    """Most change of the fingertip's tilt the inverse kinematics asks for in one step (rad per control step)."""
    rise_before_repeat: bool = False
    """Whether a finger that strikes again the key it has let go of, its tip still under the key's top and
    under its strike's path (the repeat sooner than its strike from the ready height takes), rises before
    it strikes (:meth:`~pianobot.pianist.strikes.StrikePlanner._approach`). Off, the default (the
    Allegro-like hand's, whose figures stay as measured), such a strike goes down from where the tip is:
    on a key that never rose, and the repeats do not sound."""
    repeat_rise: float = math.inf
    """How far over the depth at which a key lets its note go (the keyboard's ``release_fraction``) a
    finger that has just let go of the key rises before it strikes it again, as a piano's key is
    struck again before it is all the way up (m; ``math.inf``, the default: to the ready height over
    the key's top, as every other strike, the Allegro-like hand's)."""
    end_rise: float = math.inf
    """How far under the depth at which a key lets its note go (the keyboard's ``release_fraction``) a
    finger lets the key it holds rise in the note's last control step, so that the key, still sounding,
    has less to rise once the note's rows end and its note ends sooner after its written end (m;
    ``math.inf``, the default, the Allegro-like hand's: held at the full depth to the end)."""
    let_up_height: float = math.inf
    """Under the hold guard (:class:`~pianobot.perform.guard.HoldGuard`): a holding finger whose tip has
    risen this far over its key's top let the key up, and its note ended; the guard's teacher leaves the
    key up while the note is still written to sound (pressed again it would sound twice). A key let go
    less far is pressed on (m; ``math.inf``, the default: every held key is pressed on, as the
    Allegro-like hand's guard always did)."""


def tuning_for(hand: HandConfig) -> PianistTuning:
    """The tuning of ``hand``'s model: the defaults, with what its model sets
    (:attr:`~pianobot.sim.hand.HandModel.tuning`)."""
    return replace(PianistTuning(), **dict(hand.model.tuning))
