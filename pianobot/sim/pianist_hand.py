"""The pianist's hand: five fingers of human size, thumb to little (``--hand-model pianist``).

A hand model is one module like this one: it makes a :class:`~pianobot.sim.hand.HandModel` and
registers it. Where each figure comes from (the Shadow Dexterous Hand's proportions and motors):
docs/simulator.md#pianist; how its settings were chosen: docs/history.md.
"""

from __future__ import annotations

from pianobot.sim.hand import FingerGeometry, HandModel, register_hand_model

PIANIST = HandModel(
    name="pianist",
    bases=((1, -0.055, 0.0), (2, -0.033, 0.0), (3, -0.011, 0.0), (4, 0.011, 0.0), (5, 0.033, 0.0)),
    geometry=FingerGeometry(
        base_to_mcp=0.004,
        proximal=0.045,
        middle=0.025,
        distal=0.026,
        tip_radius=0.0085,
        link_radius=0.0075,
        abduction_limit=0.349,
        flexion_limits=((-0.35, 1.57), (0.0, 1.92), (-0.17, 1.4)),
    ),
    finger_sets=((1, 2, 3, 4, 5),),
    abduction=((1, 0.6),),
    tuning=(
        ("legato_cost", 10.0),
        ("hold_reach", 0.014),
        ("strike_reach", 0.014),
        ("black_strike_reach", 0.009),
        ("hold_slide", 0.004),
        ("max_strike_speed", 0.2),
        ("reach_fraction", 0.95),
        ("settle_time", 0.05),
        ("thumb_stretch", 0.5),
        ("prepare_steps", 2),
        ("strike_slide", 0.004),
        ("let_up_height", 0.008),
        ("travel_share", 0.75),
        ("rise_before_repeat", True),
        ("repeat_rise", 0.001),
        ("lift_steps", 0),
        ("lone_strike_wrist_steps", 1),
        ("end_rise", 0.001),
    ),
    passes=frozenset({(1, 2), (1, 3), (1, 4)}),
    written_fingering=True,
    lends_notes=True,
    settings=(
        ("palm_height", 0.0575),
        ("palm_y", 0.1575),
        ("max_joint_speed", 8.0),
        ("joint_force", 1.0),
        ("max_joint_torque", 1.0),
        ("finger_mass", 0.02),
    ),
)
"""A pianist's hand of human size (the Shadow hand's proportions, docs/simulator.md): five fingers,
thumb to little, their knuckles 22 mm apart, phalanges 45, 25 and 26 mm, a human finger's joint
ranges, the Shadow hand's joint speed and torque. The thumb is a finger like the others beside the
index (as the Allegro-like hand's) that turns farther sideways (0.6 rad either way, as a thumb
reaches under the palm); it passes under the index, middle and ring fingers and they over it
(:attr:`HandModel.passes`: the fingering planner lets their fingertips cross; turned to its limit
its tip reaches one white key past a held index, but not past a held middle finger, so a 1 2 3 1 in
a scale shifts the hand: docs/simulator.md). Its planner holds
notes to their written end as a pianist does (a higher ``legato_cost``), so it fingers a
one-octave scale with the thumb under rather than after the fifth finger. Its fingers turn sideways less far than the
Allegro-like hand's longer ones, so the wrist strays less from straight over a held or struck
key (``hold_reach``, ``strike_reach``; the thumb's as far farther as it turns) and slides more
slowly while a finger holds one (``hold_slide``); and its joints, at the Shadow hand's speed,
strike no faster than 0.2 m/s (``max_strike_speed``: about MIDI velocity 97 on a white key). Its
planner uses 95 % of each finger's sideways reach (``reach_fraction``; the Allegro-like hand's
75 %): the scripted pianist strikes a key only once the fingertip is over it, and its fingers
land there turned to their limit, so the wider margin only forbade spans the hand plays (a fifth
with fingers 2 and 5). Its planner leaves one control step (``settle_time`` 0.05 s; the
Allegro-like hand's 0.2 s) around a wrist move for its light fingers to lift and settle, so the
reduction gives the hands the quick hand shifts its scripted pianist plays; and its fingers take
two control steps, not the Allegro-like hand's four, to lift, move over and settle before a strike
(``prepare_steps``), so a key held before a hand move is let go that much nearer its written end. Its thumb pays half a
finger's stretch cost in the planner (``thumb_stretch``), so a one-octave scale is fingered with the
thumb under (1 2 3 1 2 3 4 5, 0.15-1 s a note), as pianists finger it, rather than shifting the whole
hand after the fifth finger (over two octaves it still shifts after the fifth). While a fingertip is on its way into its key the wrist slides at most 4 mm a control step
(``strike_slide``, as while a finger holds one): a thumb turned towards its key lags a quicker
slide and was dragged off it. Under the hold guard, a held key whose fingertip has risen 8 mm over
it stays up until its note ends (``let_up_height``): pressed again, it would sound twice. The strike
planner counts on its fingertips covering three quarters of their longest positioning move a step
(``travel_share``), so a held key is let go early enough for its finger's far move (from a black key
across to a white one) to strike on time, and the fingering planner gives a finger that time between
its notes. A finger that strikes again the key it has let go of rises from it first
(``rise_before_repeat``): pressed on from the bottom of a key that never rose, soft repeats written
for one finger did not sound. It strikes it again from 1 mm over the depth at which the key let its
note go (``repeat_rise``), as a piano's key is struck again before it is all the way up, so the note
before is held nearer its written end (risen to the ready height, a soft one was let go 0.15-0.3 s
early). A holding finger whose own next strike needs the wrist elsewhere lets go when its way there
must begin (``lift_steps`` 0): that way starts with its rise, and the wrist slides while the finger
moves on, so one more step for the rise held every such chord's notes a step shorter."""

register_hand_model(PIANIST)
