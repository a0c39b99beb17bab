"""The PyBullet world: keyboard and hand in one physics client, stepped at the control rate.

:class:`PianoWorld` knows physics only, no score: it takes a normalised action, runs the
physics steps of one control step, and reports what the keyboard sounded (note-on/off events
with velocities and the finger that touched each key) and the state the observations are
built from.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass, field

import numpy as np

from pianobot.config import check_ranges
from pianobot.music.tensor import ScoreSpec
from pianobot.sim.bullet import p
from pianobot.sim.hand import HandConfig, hand_urdf, joint_limits, joint_names
from pianobot.sim.keyboard import (
    KeyboardConfig,
    KeyEvent,
    KeySensor,
    key_boxes,
    key_colour,
    key_urdf,
    keyboard_width,
)

CONTROL_MODES = ("velocity", "position", "torque")
LIMIT_STOP_TORQUE = 5.0
"""Torque (N m) with which a joint's mechanical stop holds it at its limit under torque control."""


@dataclass(frozen=True)
class WorldConfig:
    """Physics settings and the two bodies."""

    keyboard: KeyboardConfig = field(default_factory=KeyboardConfig)
    hand: HandConfig = field(default_factory=HandConfig)
    physics_hz: float = 240.0
    """Physics steps per second (500 Hz cost twice as much and showed no benefit)."""
    control_hz: float = ScoreSpec.control_hz
    """Control steps per second; each runs physics_hz / control_hz physics steps (the score's rate)."""
    solver_iterations: int = 50
    """Constraint solver iterations per physics step (PyBullet's default). At 15 the env steps 1.5x
    as fast, but the last finger's joints do not follow a large commanded move (docs/simulator.md)."""
    control: str = "velocity"
    """Finger joint control: 'velocity' (action = joint speed), 'position' (action = joint angle
    target, -1 and 1 at the joint's limits) or 'torque' (action = joint torque)."""
    discrete_wrist: bool = False
    """If True the wrist action picks one of the white keys' positions and the wrist servoes there."""
    gui: bool = False
    """Open PyBullet's window instead of running headless."""

    def __post_init__(self) -> None:
        if self.control not in CONTROL_MODES:
            raise ValueError(f"control must be one of {', '.join(CONTROL_MODES)}; got {self.control!r}")
        check_ranges(self, physics_hz=(1.0, 10_000.0), control_hz=(0.1, self.physics_hz), solver_iterations=(1, 1000))

    @property
    def substeps(self) -> int:
        return max(1, int(round(self.physics_hz / self.control_hz)))


@dataclass
class StepResult:
    """What one control step did."""

    events: list[KeyEvent]
    """Note-on/off events, in time order."""
    fingers: dict[int, int]
    """For every note-on in ``events``: pitch -> the finger that touched the key (if one did)."""
    pressed: np.ndarray
    """Keys that sounded at any time during the step (bool, one per key)."""
    pressed_velocity: np.ndarray
    """Their note-on velocity (int, 0 where not pressed)."""


RAY_GROUP, HAND_GROUP, KEY_GROUP = 1, 2, 4
"""Collision groups: a key collides with the hands only (the keys' boxes overlap where the black
keys sit between the white ones), a hand with the keys and with other hands; ray tests (in
PyBullet's default group) see both."""
KEY_AT_REST = (1e-4, 1e-3)
"""A key whose angle (rad) and angular speed (rad/s) are both below these, and that no fingertip
touches, is at rest: it sleeps (PyBullet leaves it out of the physics until a finger touches it)
and is not read."""


class PianoWorld:
    """One PyBullet client holding the keys (one body each) and the hand.

    Cost: the physics of a key no finger touches is skipped (it sleeps at rest), and only the
    keys that move or are touched are read at each physics step, so a step costs what the hand
    does, whatever the keyboard's size."""

    def __init__(self, config: WorldConfig = WorldConfig()):
        self.config = config
        self.client = p.connect(p.GUI if config.gui else p.DIRECT)
        self.dt = 1.0 / config.physics_hz
        self.boxes = key_boxes(config.keyboard)
        self.width = keyboard_width(config.keyboard)
        self.sensor = KeySensor(config.keyboard)
        self.time = 0.0
        self._finger_command = np.zeros(4 * len(config.hand.spec.fingers))
        self._build()
        if config.gui:
            p.resetDebugVisualizerCamera(0.45, 180, -60, [self.width / 2, 0.11, 0], physicsClientId=self.client)

    # -- construction ------------------------------------------------------------------------
    def _build(self) -> None:
        """(Re)create the physics world: settings, keys and hand, everything at rest."""
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
        self.hand, self.wrist_joint, self.finger_joints, self.tip_links = self._build_hand()
        n, kb = len(self.keys), self.config.keyboard
        self.key_angles, self.key_speeds = np.zeros(n), np.zeros(n)
        self._moving: set[int] = set()  # keys not at rest: read at every physics step
        self._contacts: tuple = ()  # the hand's contacts at the last physics step
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

    def _build_hand(self) -> tuple[int, int, list[int], dict[int, int]]:
        c, hand = self.client, self.config.hand
        path = self._urdf_file(hand_urdf(hand, rail=(0.0, self.width)))
        try:
            body = self._load_urdf(path, [0, hand.palm_y, hand.palm_height])
        finally:
            os.unlink(path)
        index = {
            p.getJointInfo(body, j, physicsClientId=c)[1].decode(): j
            for j in range(p.getNumJoints(body, physicsClientId=c))
        }
        fingers = [index[name] for name in joint_names(hand.spec)]
        self.joint_limits = joint_limits(hand)
        tips = {f: index[f"f{f}_dip"] for f in hand.spec.fingers}  # the DIP joint's child is the distal link
        for j in [index["wrist"], *fingers]:
            p.changeDynamics(body, j, linearDamping=0, angularDamping=0, physicsClientId=c)
        for link in tips.values():
            p.changeDynamics(body, link, lateralFriction=0.8, physicsClientId=c)
        for link in range(-1, p.getNumJoints(body, physicsClientId=c)):
            p.setCollisionFilterGroupMask(body, link, HAND_GROUP, KEY_GROUP | HAND_GROUP | RAY_GROUP, physicsClientId=c)
        return body, index["wrist"], fingers, tips

    # -- state -------------------------------------------------------------------------------
    def reset(self, wrist: float, finger_angles: np.ndarray) -> None:
        """Put the hand at ``wrist`` (m along the keyboard) with the given joint angles, keys at rest."""
        c = self.client
        # a fresh world: no contact cache or solver warm start carries over, so an episode does
        # not depend on the ones before it (tested; PyBullet's saveState/restoreState left some)
        self._build()
        p.resetJointState(self.hand, self.wrist_joint, wrist, 0.0, physicsClientId=c)
        for j, angle in zip(self.finger_joints, finger_angles):
            p.resetJointState(self.hand, j, float(angle), 0.0, physicsClientId=c)
        self.sensor.reset()
        self.time = 0.0
        # no speed, no torque, or (position control) the angles it starts at
        position = self.config.control == "position"
        self._finger_command = np.array(finger_angles, dtype=float) if position else np.zeros(len(self.finger_joints))
        self._drive_wrist(p.POSITION_CONTROL, targetPosition=wrist)  # motors hold the pose until the first action
        self._finger_motors(p.VELOCITY_CONTROL, targetVelocities=np.zeros(len(self.finger_joints)))

    def key_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Key angles (rad) and angular speeds (rad/s), as of the last physics step (a key at rest
        reads as it was when it came to rest)."""
        return self.key_angles.copy(), self.key_speeds.copy()

    def hand_state(self) -> tuple[float, float, np.ndarray, np.ndarray]:
        """Wrist position (m) and speed (m/s), finger joint angles and speeds."""
        c = self.client
        wrist = p.getJointState(self.hand, self.wrist_joint, physicsClientId=c)
        states = p.getJointStates(self.hand, self.finger_joints, physicsClientId=c)
        return wrist[0], wrist[1], np.array([s[0] for s in states]), np.array([s[1] for s in states])

    def _key_contacts(self) -> list[tuple[int, int, float]]:
        """(key index, hand link, normal force) of every contact between the hand and a key now."""
        key_of = self._key_of
        return [(key_of[ct[2]], ct[3], ct[9]) for ct in self._contacts if ct[2] in key_of]

    def touching(self) -> dict[int, tuple[int, float]]:
        """Key index -> (finger, normal force) for every key a fingertip presses on now."""
        out: dict[int, tuple[int, float]] = {}
        finger_of = {link: f for f, link in self.tip_links.items()}
        for key, link, force in self._key_contacts():
            finger = finger_of.get(link)
            if finger is not None and force > out.get(key, (0, 0.0))[1]:
                out[key] = (finger, force)
        return out

    def tip_points(self) -> dict[int, np.ndarray]:
        """World position of each fingertip's lowest point (the bottom of its tip sphere)."""
        g = self.config.hand.geometry
        points = {}
        for finger, link in self.tip_links.items():
            position, rotation = self.link_pose(link)
            points[finger] = (
                position + rotation @ np.array([0.0, -(g.distal - g.tip_radius), 0.0]) - np.array([0, 0, g.tip_radius])
            )
        return points

    def tip_forces(self) -> dict[int, float]:
        """Total normal force (N) on each fingertip from the keys."""
        forces = {f: 0.0 for f in self.tip_links}
        finger_of = {link: f for f, link in self.tip_links.items()}
        for _, link, force in self._key_contacts():
            finger = finger_of.get(link)
            if finger is not None:
                forces[finger] += force
        return forces

    def link_pose(self, link: int) -> tuple[np.ndarray, np.ndarray]:
        """World position and rotation matrix of a hand link's frame."""
        state = p.getLinkState(self.hand, link, computeForwardKinematics=True, physicsClientId=self.client)
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
        c, kb = self.client, self.config.keyboard
        self._contacts = p.getContactPoints(bodyA=self.hand, physicsClientId=c)
        touched = {key for key, _, _ in self._key_contacts()}
        read = sorted(self._moving | touched)
        if not read:
            return read
        for k in read:
            self.key_angles[k], self.key_speeds[k] = p.getJointState(self.keys[k], 0, physicsClientId=c)[:2]
        angles = self.key_angles[read]
        depth = np.clip(angles / kb.geometry.max_angle, 0.0, 1.0)
        torque = kb.spring_torque + (kb.spring_torque_pressed - kb.spring_torque) * depth**2
        rest_angle, rest_speed = KEY_AT_REST
        resting = (np.abs(angles) < rest_angle) & (np.abs(self.key_speeds[read]) < rest_speed)
        for k, tau, still in zip(read, torque, resting):
            if tau != self._spring[k]:
                self._spring[k] = tau
                self._set_spring(self.keys[k], tau)
            if still and k not in touched:
                self._moving.discard(k)
                p.changeDynamics(self.keys[k], 0, activationState=p.ACTIVATION_STATE_SLEEP, physicsClientId=c)
            else:
                self._moving.add(k)
        return read

    def _apply_action(self, action: np.ndarray) -> None:
        cfg, hand = self.config, self.config.hand
        n = len(self.finger_joints)
        action = np.asarray(action, dtype=float)
        if action.shape != (n + 1,):
            raise ValueError(f"action must have shape ({n + 1},): {n} finger joints then the wrist; got {action.shape}")
        action = np.clip(action, -1.0, 1.0)
        fingers, wrist = action[:n], float(action[n])
        if cfg.control == "velocity":
            self._finger_command = fingers * hand.max_joint_speed
        elif cfg.control == "position":
            low, high = self.joint_limits
            self._finger_command = low + (fingers + 1.0) / 2.0 * (high - low)
        else:
            self._finger_command = fingers * hand.max_joint_torque
            self._finger_motors(p.VELOCITY_CONTROL, forces=np.zeros(n))
        if cfg.discrete_wrist:
            target = self.discrete_wrist_position(wrist)
            self._drive_wrist(p.POSITION_CONTROL, targetPosition=target, maxVelocity=hand.max_wrist_speed)
        else:
            self._drive_wrist(p.VELOCITY_CONTROL, targetVelocity=wrist * hand.max_wrist_speed)

    def _drive_wrist(self, mode: int, **target: float) -> None:
        """The wrist's motor in ``mode`` towards ``target`` (pybullet's targetPosition, maxVelocity,
        targetVelocity), with at most the hand's wrist force."""
        p.setJointMotorControl2(
            self.hand,
            self.wrist_joint,
            mode,
            force=self.config.hand.wrist_force,
            physicsClientId=self.client,
            **target,
        )

    def _finger_motors(self, mode: int, **arrays: np.ndarray) -> None:
        """Every finger joint's motor in ``mode`` (velocity motors at most the hand's joint force,
        unless ``forces`` says otherwise)."""
        if mode == p.VELOCITY_CONTROL and "forces" not in arrays:
            arrays["forces"] = np.full(len(self.finger_joints), self.config.hand.joint_force)
        lists = {name: np.asarray(values, dtype=float).tolist() for name, values in arrays.items()}
        p.setJointMotorControlArray(self.hand, self.finger_joints, mode, physicsClientId=self.client, **lists)

    def _drive_fingers(self, torque: bool, left: int) -> None:
        """Apply the finger command for one physics step, never driving a joint past its limit.
        ``left``: physics steps left in the control step, this one included.

        Position control moves each joint at the constant speed that reaches its target when the
        control step ends (velocity control's path when the target is angle + speed x step), up
        to ``max_joint_speed``; the next target is absolute, so an error does not carry over.

        PyBullet's joint limits are soft: a finger motor at full speed pushes the light finger
        links far past them (we saw the PIP joint at -1.5 rad against a limit of -0.17). So the
        commanded speed is clipped to what reaches the limit within one physics step, and a
        joint that would pass a limit under torque control is held at it by a motor."""
        hand = self.config.hand
        states = p.getJointStates(self.hand, self.finger_joints, physicsClientId=self.client)
        q = np.array([s[0] for s in states])
        low, high = self.joint_limits
        # speeds that reach a limit within this physics step, and no further
        slowest, fastest = (low - q) / self.dt, (high - q) / self.dt
        if not torque:
            command = self._finger_command
            if self.config.control == "position":  # at the speed that reaches the target at the control step's end
                command = np.clip((command - q) / (left * self.dt), -hand.max_joint_speed, hand.max_joint_speed)
            self._finger_motors(p.VELOCITY_CONTROL, targetVelocities=np.clip(command, slowest, fastest))
            return
        # torque control, except for joints that would pass a limit within this step: a motor holds those at it
        velocity = np.array([s[1] for s in states])
        tau = self._finger_command
        guard = (velocity > fastest) | (velocity < slowest) | ((q >= high) & (tau > 0)) | ((q <= low) & (tau < 0))
        self._finger_motors(
            p.VELOCITY_CONTROL,
            targetVelocities=np.clip(0.0, slowest, fastest),
            forces=np.where(guard, LIMIT_STOP_TORQUE, 0.0),
        )
        self._finger_motors(p.TORQUE_CONTROL, forces=np.where(guard, 0.0, tau))

    def discrete_wrist_position(self, action: float) -> float:
        """The white-key position that a wrist action in [-1, 1] selects."""
        centres = [b.center[0] for b in self.boxes if not b.black]
        index = int(round((np.clip(action, -1, 1) + 1) / 2 * (len(centres) - 1)))
        return centres[index]

    def step(self, action: np.ndarray) -> StepResult:
        """One control step: apply ``action`` (finger joints then wrist, each in [-1, 1]) and run the physics."""
        self._apply_action(action)
        events: list[KeyEvent] = []
        fingers: dict[int, int] = {}
        pressed = self.sensor.sounding.copy()
        pressed_velocity = self.sensor.velocity.copy()
        torque = self.config.control == "torque"
        lowest = self.config.keyboard.spec.lowest
        for substep in range(self.config.substeps):
            self._drive_fingers(torque, self.config.substeps - substep)
            p.stepSimulation(physicsClientId=self.client)
            self.time += self.dt
            if not self._update_keys():
                continue  # every key at rest: nothing can sound or release
            new = self.sensor.update(self.time, self.key_angles, self.key_speeds)
            if new:
                touch = self.touching()
                for event in new:
                    key = event.pitch - lowest
                    if event.on and key in touch:
                        fingers[event.pitch] = touch[key][0]
                events += new
                self._colour_keys(new)
                pressed |= self.sensor.sounding
                pressed_velocity = np.maximum(pressed_velocity, self.sensor.velocity)
        return StepResult(events, fingers, pressed, pressed_velocity)

    # -- images ------------------------------------------------------------------------------
    def _colour_keys(self, events: list[KeyEvent]) -> None:
        """Sounding keys turn blue, so pressed keys show in frames and videos."""
        lowest = self.config.keyboard.spec.lowest
        for event in events:
            key = event.pitch - lowest
            colour = key_colour(self.boxes[key].black, event.on)
            p.changeVisualShape(self.keys[key], 0, rgbaColor=colour, physicsClientId=self.client)

    def render(self, width: int = 480, height: int = 320) -> np.ndarray:
        """An RGB frame (height, width, 3) from a camera above the pianist's side of the keyboard.

        The world is built with the pianist on the +y side, which makes it the mirror image of a
        real piano (low notes on the pianist's right); the frame is mirrored back, so it shows
        the keyboard and the right hand as a pianist sees them.
        """
        c = self.client
        target = [self.width / 2, 0.11, 0.0]
        view = p.computeViewMatrixFromYawPitchRoll(target, 0.42, 180, -68, 0, 2, physicsClientId=c)
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
