"""The PyBullet world: keyboard and hand in one physics client, stepped at the control rate.

:class:`PianoWorld` knows physics only, no score: it takes a normalised action, runs the
physics steps of one control step, and reports what the keyboard sounded (note-on/off events
with velocities and the finger that touched each key) and the state the observations are
built from.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence

import numpy as np

from pianobot.sim.bullet import p
from pianobot.sim.hand import SIDES, hand_urdf, joint_limits, joint_names, thumb_side_reach
from pianobot.sim.keyboard import (
    KeyEvent,
    KeySensor,
    key_boxes,
    key_colour,
    key_urdf,
    keyboard_width,
)
from pianobot.sim.world_config import LIMIT_STOP_TORQUE, HandBody, StepResult, WorldConfig

RAY_GROUP, HAND_GROUP, KEY_GROUP = 1, 2, 4
"""Collision groups: a key collides with the hands only (the keys' boxes overlap where the black
keys sit between the white ones), a hand with the keys and with other hands; ray tests (in
PyBullet's default group) see both."""
KEY_AT_REST = (1e-4, 1e-3)
"""A key whose angle (rad) and angular speed (rad/s) are both below these, and that no fingertip
touches, is at rest: it sleeps (PyBullet leaves it out of the physics until a finger touches it)
and is not read."""


class PianoWorld:
    """One PyBullet client holding the keys (one body each) and one hand, or two.

    ``hands``: the sides of the hands, in the order their actions come: ("right",) (default), or
    ("right", "left"), the left hand being the right's mirror image (:data:`~pianobot.sim.hand.SIDES`).
    Each hand slides on its own rail along the whole keyboard; the two never cross: the world
    keeps the right wrist at least :attr:`min_separation` above the left one (so their finger
    bases never meet), and their links collide with each other's (so abducted fingers touch
    rather than pass).

    Cost: the physics of a key no finger touches is skipped (it sleeps at rest), and only the
    keys that move or are touched are read at each physics step, so a step costs what the hands
    do, whatever the keyboard's size."""

    def __init__(self, config: WorldConfig = WorldConfig(), hands: tuple[str, ...] = ("right",)):
        if not 1 <= len(hands) <= 2 or len(set(hands)) != len(hands) or set(hands) - set(SIDES):
            raise ValueError(f"hands must be one or two different sides of {', '.join(SIDES)}; got {hands}")
        self.config = config
        self.sides = tuple(hands)
        self.client = p.connect(p.GUI if config.gui else p.DIRECT)
        self.dt = 1.0 / config.physics_hz
        self.boxes = key_boxes(config.keyboard)
        self.width = keyboard_width(config.keyboard)
        self.sensor = KeySensor(config.keyboard)
        self.joint_limits = joint_limits(config.hand)
        """(2, 4F): every finger joint's lower and upper limit (rad), for each hand alike."""
        self.min_separation = 2 * thumb_side_reach(config.hand)
        """Least distance (m) between two hands' wrists, the right one above."""
        self.time = 0.0
        self._finger_command = np.zeros((len(hands), len(joint_names(config.hand.spec))))
        self._build()
        if config.gui:
            p.resetDebugVisualizerCamera(0.45, 180, -60, [self.width / 2, 0.11, 0], physicsClientId=self.client)

    # the first hand's body and joints (all there is of a one-hand world)
    @property
    def hand(self) -> int:
        return self.hands[0].body

    @property
    def wrist_joint(self) -> int:
        return self.hands[0].wrist

    @property
    def finger_joints(self) -> list[int]:
        return list(self.hands[0].fingers)

    @property
    def tip_links(self) -> dict[int, int]:
        return self.hands[0].tips

    # -- construction ------------------------------------------------------------------------
    def _build(self) -> None:
        """(Re)create the physics world: settings, keys and hands, everything at rest."""
        c = self.client
        p.resetSimulation(physicsClientId=c)
        p.setTimeStep(self.dt, physicsClientId=c)
        # No gravity: the hand is gravity-compensated, as the Allegro's own controller makes it, and a
        # key's weight is part of its return spring. (With gravity, 15 solver iterations let light
        # finger links sag under their motors.)
        p.setGravity(0, 0, 0, physicsClientId=c)
        p.setPhysicsEngineParameter(numSolverIterations=self.config.solver_iterations, physicsClientId=c)
        self.keys = self._build_keys()
        self._key_of = {body: k for k, body in enumerate(self.keys)}
        self.hands = [self._build_hand(side) for side in self.sides]
        n, kb = len(self.keys), self.config.keyboard
        self.key_angles, self.key_speeds = np.zeros(n), np.zeros(n)
        self._moving: set[int] = set()  # keys not at rest: read at every physics step
        self._contacts: list[tuple[int, int, int, float]] = []  # (key, hand, link, force) at the last physics step
        self._spring = np.full(n, kb.spring_torque)
        for body in self.keys:
            self._set_spring(body, kb.spring_torque)
            p.changeDynamics(body, 0, activationState=p.ACTIVATION_STATE_SLEEP, physicsClientId=c)

    def _load_urdf(self, path: str, position: list[float]) -> int:
        return p.loadURDF(path, basePosition=position, useFixedBase=True, physicsClientId=self.client)

    def _urdf_file(self, text: str) -> str:
        fd, path = tempfile.mkstemp(prefix="pianobot_", suffix=".urdf")
        with os.fdopen(fd, "w") as f:
            f.write(text)
        return path

    def _build_keys(self) -> list[int]:
        """One body per key, each hinged at its x: a key's joint then costs the physics what one
        joint costs (the keys of one body shared every joint's constraints, a cost that grew with
        the square of the keys), and a key at rest can sleep."""
        c, kb = self.client, self.config.keyboard
        files = {}
        bodies = []
        try:
            for box in self.boxes:
                shape = (box.black, box.center[1:], box.half)  # a white or a black key
                if shape not in files:
                    files[shape] = self._urdf_file(key_urdf(kb, box))
                body = self._load_urdf(files[shape], [box.center[0], 0, 0])
                p.changeDynamics(
                    body,
                    0,
                    linearDamping=0,
                    angularDamping=0,
                    activationState=p.ACTIVATION_STATE_ENABLE_SLEEPING,
                    physicsClientId=c,
                )
                for link in (-1, 0):
                    p.setCollisionFilterGroupMask(body, link, KEY_GROUP, HAND_GROUP | RAY_GROUP, physicsClientId=c)
                bodies.append(body)
        finally:
            for path in files.values():
                os.unlink(path)
        return bodies

    def _build_hand(self, side: str) -> HandBody:
        c, hand = self.client, self.config.hand
        path = self._urdf_file(hand_urdf(hand, rail=(0.0, self.width), side=side))
        try:
            body = self._load_urdf(path, [0, hand.palm_y, hand.palm_height])
        finally:
            os.unlink(path)
        index = {
            p.getJointInfo(body, j, physicsClientId=c)[1].decode(): j
            for j in range(p.getNumJoints(body, physicsClientId=c))
        }
        fingers = tuple(index[name] for name in joint_names(hand.spec))
        tips = {f: index[f"f{f}_dip"] for f in hand.spec.fingers}  # the DIP joint's child is the distal link
        for j in [index["wrist"], *fingers]:
            p.changeDynamics(body, j, linearDamping=0, angularDamping=0, physicsClientId=c)
        for link in tips.values():
            p.changeDynamics(body, link, lateralFriction=0.8, physicsClientId=c)
        for link in range(-1, p.getNumJoints(body, physicsClientId=c)):
            p.setCollisionFilterGroupMask(body, link, HAND_GROUP, KEY_GROUP | HAND_GROUP | RAY_GROUP, physicsClientId=c)
        return HandBody(side, body, index["wrist"], fingers, tips)

    # -- state -------------------------------------------------------------------------------
    def reset(self, wrist: float | Sequence[float], finger_angles: np.ndarray) -> None:
        """Put each hand at its ``wrist`` position (m along the keyboard; one number for one hand)
        with the given joint angles (every hand's, one after the other: or one hand's, for all),
        keys at rest."""
        c = self.client
        wrists = np.atleast_1d(np.asarray(wrist, dtype=float))
        angles = np.asarray(finger_angles, dtype=float).reshape(-1, self._finger_command.shape[1])
        if len(wrists) != len(self.sides) or len(angles) not in (1, len(self.sides)):
            raise ValueError(f"give a wrist position for each of the {len(self.sides)} hands, and their joint angles")
        angles = np.broadcast_to(angles, self._finger_command.shape)
        self._check_apart(wrists)
        # a fresh world: no contact cache or solver warm start carries over, so an episode does
        # not depend on the ones before it (tested; PyBullet's saveState/restoreState left some)
        self._build()
        for hand, x, q in zip(self.hands, wrists, angles):
            p.resetJointState(hand.body, hand.wrist, x, 0.0, physicsClientId=c)
            for j, angle in zip(hand.fingers, q):
                p.resetJointState(hand.body, j, float(angle), 0.0, physicsClientId=c)
            self._drive_wrist(hand, p.POSITION_CONTROL, targetPosition=x)  # motors hold the pose until the first action
            self._finger_motors(hand, p.VELOCITY_CONTROL, targetVelocities=np.zeros(len(hand.fingers)))
        self.sensor.reset()
        self.time = 0.0
        # no speed, no torque, or (position control) the angles it starts at
        self._finger_command = angles.copy() if self.config.control == "position" else np.zeros(angles.shape)

    def _check_apart(self, wrists: np.ndarray) -> None:
        if len(self.sides) == 2:
            low, high = wrists[self.sides.index("left")], wrists[self.sides.index("right")]
            if high - low < self.min_separation - 1e-9:
                raise ValueError(
                    f"the right wrist ({high:.3f} m) must be at least {self.min_separation:.3f} m above the left ({low:.3f} m)"
                )

    def key_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Key angles (rad) and angular speeds (rad/s), as of the last physics step (a key at rest
        reads as it was when it came to rest)."""
        return self.key_angles.copy(), self.key_speeds.copy()

    def hand_state(self, hand: int = 0) -> tuple[float, float, np.ndarray, np.ndarray]:
        """A hand's wrist position (m) and speed (m/s), finger joint angles and speeds."""
        c, h = self.client, self.hands[hand]
        wrist = p.getJointState(h.body, h.wrist, physicsClientId=c)
        states = p.getJointStates(h.body, h.fingers, physicsClientId=c)
        return wrist[0], wrist[1], np.array([s[0] for s in states]), np.array([s[1] for s in states])

    def touching(self, hand: int = 0) -> dict[int, tuple[int, float]]:
        """Key index -> (finger, normal force) for every key a fingertip of ``hand`` presses on now."""
        out: dict[int, tuple[int, float]] = {}
        finger_of = {link: f for f, link in self.hands[hand].tips.items()}
        for key, h, link, force in self._contacts:
            finger = finger_of.get(link) if h == hand else None
            if finger is not None and force > out.get(key, (0, 0.0))[1]:
                out[key] = (finger, force)
        return out

    def tip_points(self, hand: int = 0) -> dict[int, np.ndarray]:
        """World position of each fingertip's lowest point (the bottom of its tip sphere)."""
        g = self.config.hand.geometry
        points = {}
        for finger, link in self.hands[hand].tips.items():
            position, rotation = self.link_pose(link, hand)
            points[finger] = (
                position + rotation @ np.array([0.0, -(g.distal - g.tip_radius), 0.0]) - np.array([0, 0, g.tip_radius])
            )
        return points

    def tip_forces(self, hand: int = 0) -> dict[int, float]:
        """Total normal force (N) on each fingertip of ``hand`` from the keys."""
        tips = self.hands[hand].tips
        forces = {f: 0.0 for f in tips}
        finger_of = {link: f for f, link in tips.items()}
        for _, h, link, force in self._contacts:
            if h == hand and link in finger_of:
                forces[finger_of[link]] += force
        return forces

    def link_pose(self, link: int, hand: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """World position and rotation matrix of a hand link's frame."""
        body = self.hands[hand].body
        state = p.getLinkState(body, link, computeForwardKinematics=True, physicsClientId=self.client)
        rotation = np.array(p.getMatrixFromQuaternion(state[5], physicsClientId=self.client)).reshape(3, 3)
        return np.array(state[4]), rotation

    # -- stepping ----------------------------------------------------------------------------
    def _set_spring(self, body: int, torque: float) -> None:
        """A key's return spring: a motor driving back to rest with at most ``torque``."""
        kb = self.config.keyboard
        p.setJointMotorControl2(
            body,
            0,
            p.POSITION_CONTROL,
            targetPosition=0.0,
            positionGain=kb.spring_gain,
            force=torque,
            physicsClientId=self.client,
        )

    def _update_keys(self) -> list[int]:
        """After a physics step: read the keys that move or are touched, retune their springs (the
        torque limit grows with depth), put those back at rest to sleep. Returns the keys read."""
        c, kb, key_of = self.client, self.config.keyboard, self._key_of
        self._contacts = [
            (key_of[ct[2]], h, ct[3], ct[9])
            for h, hand in enumerate(self.hands)
            for ct in p.getContactPoints(bodyA=hand.body, physicsClientId=c)
            if ct[2] in key_of
        ]
        touched = {key for key, *_ in self._contacts}
        read = sorted(self._moving | touched)
        max_angle, rest, pressed = kb.geometry.max_angle, kb.spring_torque, kb.spring_torque_pressed
        rest_angle, rest_speed = KEY_AT_REST
        for k in read:  # a few keys: plain Python is quicker than NumPy here
            angle, speed = p.getJointState(self.keys[k], 0, physicsClientId=c)[:2]
            self.key_angles[k], self.key_speeds[k] = angle, speed
            depth = min(max(angle / max_angle, 0.0), 1.0)
            torque = rest + (pressed - rest) * depth**2
            if torque != self._spring[k]:
                self._spring[k] = torque
                self._set_spring(self.keys[k], torque)
            if abs(angle) < rest_angle and abs(speed) < rest_speed and k not in touched:
                self._moving.discard(k)
                p.changeDynamics(self.keys[k], 0, activationState=p.ACTIVATION_STATE_SLEEP, physicsClientId=c)
            else:
                self._moving.add(k)
        return read

    def _apply_action(self, action: np.ndarray) -> None:
        cfg, hand = self.config, self.config.hand
        h, n = self._finger_command.shape
        action = np.asarray(action, dtype=float)
        if action.shape != (h * (n + 1),):
            raise ValueError(
                f"action must have shape ({h * (n + 1)},): for each of {h} hands, {n} finger joints then the wrist; "
                f"got {action.shape}"
            )
        action = np.clip(action, -1.0, 1.0).reshape(h, n + 1)
        fingers, wrists = action[:, :n], action[:, n]
        if cfg.control == "velocity":
            self._finger_command = fingers * hand.max_joint_speed
        elif cfg.control == "position":
            low, high = self.joint_limits
            self._finger_command = low + (fingers + 1.0) / 2.0 * (high - low)
        else:
            self._finger_command = fingers * hand.max_joint_torque
            for body in self.hands:
                self._finger_motors(body, p.VELOCITY_CONTROL, forces=np.zeros(n))
        if cfg.discrete_wrist:
            targets = self._apart_targets(np.array([self.discrete_wrist_position(w) for w in wrists]))
            for body, target in zip(self.hands, targets):
                self._drive_wrist(body, p.POSITION_CONTROL, targetPosition=target, maxVelocity=hand.max_wrist_speed)
        else:
            for body, speed in zip(self.hands, self._apart_speeds(wrists * hand.max_wrist_speed)):
                self._drive_wrist(body, p.VELOCITY_CONTROL, targetVelocity=speed)

    def _wrists(self) -> np.ndarray:
        return np.array([p.getJointState(h.body, h.wrist, physicsClientId=self.client)[0] for h in self.hands])

    def _apart_speeds(self, speeds: np.ndarray) -> np.ndarray:
        """Wrist speeds with the hands' closing speed cut to what keeps them :attr:`min_separation`
        apart at the end of the control step (one hand: as they are)."""
        if len(self.hands) == 1:
            return speeds
        left, right = self.sides.index("left"), self.sides.index("right")
        x = self._wrists()
        room = max(x[right] - x[left] - self.min_separation, 0.0)
        closing = np.array([max(speeds[left], 0.0), max(-speeds[right], 0.0)])
        travel = closing.sum() * self.config.substeps * self.dt
        if travel > room:
            cut = closing * (1.0 - room / travel)
            speeds = speeds.copy()
            speeds[left] -= cut[0]
            speeds[right] += cut[1]
        return speeds

    def _apart_targets(self, targets: np.ndarray) -> np.ndarray:
        """Wrist targets at least :attr:`min_separation` apart (the left one gives way, then the right)."""
        if len(self.hands) == 1:
            return targets
        left, right = self.sides.index("left"), self.sides.index("right")
        targets = targets.copy()
        targets[left] = max(min(targets[left], targets[right] - self.min_separation), 0.0)
        targets[right] = max(targets[right], targets[left] + self.min_separation)
        return targets

    def _drive_wrist(self, hand: HandBody, mode: int, **target: float) -> None:
        """A wrist's motor in ``mode`` towards ``target`` (pybullet's targetPosition, maxVelocity,
        targetVelocity), with at most the hand's wrist force."""
        p.setJointMotorControl2(
            hand.body,
            hand.wrist,
            mode,
            force=self.config.hand.wrist_force,
            physicsClientId=self.client,
            **target,
        )

    def _finger_motors(self, hand: HandBody, mode: int, **arrays: np.ndarray) -> None:
        """Every finger joint's motor of ``hand`` in ``mode`` (velocity motors at most the hand's
        joint force, unless ``forces`` says otherwise)."""
        lists = {name: np.asarray(values, dtype=float).tolist() for name, values in arrays.items()}
        if mode == p.VELOCITY_CONTROL and "forces" not in lists:
            lists["forces"] = [self.config.hand.joint_force] * len(hand.fingers)
        p.setJointMotorControlArray(hand.body, hand.fingers, mode, physicsClientId=self.client, **lists)

    def _drive_fingers(self, hand: int, torque: bool, left: int) -> None:
        """Apply ``hand``'s finger command for one physics step, never driving a joint past its
        limit. ``left``: physics steps left in the control step, this one included.

        Position control moves each joint at the constant speed that reaches its target when the
        control step ends (velocity control's path when the target is angle + speed x step), up
        to ``max_joint_speed``; the next target is absolute, so an error does not carry over.

        PyBullet's joint limits are soft: a finger motor at full speed pushes the light finger
        links far past them (we saw the PIP joint at -1.5 rad against a limit of -0.17). So the
        commanded speed is clipped to what reaches the limit within one physics step, and a
        joint that would pass a limit under torque control is held at it by a motor."""
        config, body = self.config.hand, self.hands[hand]
        states = p.getJointStates(body.body, body.fingers, physicsClientId=self.client)
        q = np.array([s[0] for s in states])
        low, high = self.joint_limits
        # speeds that reach a limit within this physics step, and no further
        slowest, fastest = (low - q) / self.dt, (high - q) / self.dt
        command = self._finger_command[hand]
        if not torque:
            if self.config.control == "position":  # at the speed that reaches the target at the control step's end
                command = np.clip((command - q) / (left * self.dt), -config.max_joint_speed, config.max_joint_speed)
            # (np.minimum of np.maximum is np.clip, at a third of its cost on a few numbers)
            self._finger_motors(
                body, p.VELOCITY_CONTROL, targetVelocities=np.minimum(np.maximum(command, slowest), fastest)
            )
            return
        # torque control, except for joints that would pass a limit within this step: a motor holds those at it
        velocity = np.array([s[1] for s in states])
        guard = (
            (velocity > fastest) | (velocity < slowest) | ((q >= high) & (command > 0)) | ((q <= low) & (command < 0))
        )
        self._finger_motors(
            body,
            p.VELOCITY_CONTROL,
            targetVelocities=np.clip(0.0, slowest, fastest),
            forces=np.where(guard, LIMIT_STOP_TORQUE, 0.0),
        )
        self._finger_motors(body, p.TORQUE_CONTROL, forces=np.where(guard, 0.0, command))

    def discrete_wrist_position(self, action: float) -> float:
        """The white-key position that a wrist action in [-1, 1] selects."""
        centres = [b.center[0] for b in self.boxes if not b.black]
        index = int(round((np.clip(action, -1, 1) + 1) / 2 * (len(centres) - 1)))
        return centres[index]

    def step(self, action: np.ndarray) -> StepResult:
        """One control step: apply ``action`` (for each hand, its finger joints then its wrist, each
        in [-1, 1]) and run the physics."""
        self._apply_action(action)
        events: list[KeyEvent] = []
        fingers: dict[int, int] = {}
        hands: dict[int, int] = {}
        pressed = self.sensor.sounding.copy()
        pressed_velocity = self.sensor.velocity.copy()
        torque = self.config.control == "torque"
        lowest = self.config.keyboard.spec.lowest
        for substep in range(self.config.substeps):
            for hand in range(len(self.hands)):
                self._drive_fingers(hand, torque, self.config.substeps - substep)
            p.stepSimulation(physicsClientId=self.client)
            self.time += self.dt
            read = self._update_keys()
            if not read:
                continue  # every key at rest: nothing can sound or release
            new = self.sensor.update(self.time, self.key_angles, self.key_speeds, read)
            if new:
                touch: dict[
                    int, tuple[int, int, float]
                ] = {}  # key -> the hand, finger and force of its strongest touch
                for h in range(len(self.hands)):
                    for key, (finger, force) in self.touching(h).items():
                        if force > touch.get(key, (0, 0, 0.0))[2]:
                            touch[key] = (h, finger, force)
                for event in new:
                    key = event.pitch - lowest
                    if event.on and key in touch:
                        hands[event.pitch], fingers[event.pitch], _ = touch[key]
                events += new
                self._colour_keys(new)
                pressed |= self.sensor.sounding
                pressed_velocity = np.maximum(pressed_velocity, self.sensor.velocity)
        return StepResult(events, fingers, pressed, pressed_velocity, hands)

    # -- images ------------------------------------------------------------------------------
    def _colour_keys(self, events: list[KeyEvent]) -> None:
        """Sounding keys turn blue, so pressed keys show in frames and videos."""
        lowest = self.config.keyboard.spec.lowest
        for event in events:
            key = event.pitch - lowest
            colour = key_colour(self.boxes[key].black, event.on)
            p.changeVisualShape(self.keys[key], 0, rgbaColor=colour, physicsClientId=self.client)

    def render(self, width: int = 480, height: int = 320) -> np.ndarray:
        """An RGB frame (height, width, 3) from a camera above the pianist's side of the keyboard,
        far enough to show the whole keyboard (and no nearer than one hand's 24 keys need).

        The world is built with the pianist on the +y side, which makes it the mirror image of a
        real piano (low notes on the pianist's right); the frame is mirrored back, so it shows
        the keyboard and the right hand as a pianist sees them.
        """
        c = self.client
        target = [self.width / 2, 0.11, 0.0]
        distance = max(0.42, 1.1 * self.width / (2 * np.tan(np.radians(22.5)) * width / height))
        view = p.computeViewMatrixFromYawPitchRoll(target, distance, 180, -68, 0, 2, physicsClientId=c)
        projection = p.computeProjectionMatrixFOV(45, width / height, 0.01, 2.0, physicsClientId=c)
        _, _, rgba, _, _ = p.getCameraImage(
            width, height, view, projection, renderer=p.ER_TINY_RENDERER, physicsClientId=c
        )
        frame = np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]
        return np.ascontiguousarray(frame[:, ::-1])

    def close(self) -> None:
        if self.client is not None and p.isConnected(self.client):
            p.disconnect(self.client)
        self.client = None

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass
