"""DIGIT-like tactile images of the fingertips' gel, rendered by casting rays against the keys.

The gel is a dome over the end of each fingertip (the part that meets a key when the finger is
curled). An image is a ``rows x cols`` grid over the gel; each pixel looks along the gel's normal
and sees how far the key surface pushes into the gel:

    depth = clip(gel(u, v) + squeeze - distance to the key along the ray, 0, max_depth) / max_depth

``gel(u, v)`` is the dome's height over the sensor plane; ``squeeze = force / stiffness`` is how
much the soft gel is compressed by the normal force the keys exert on that fingertip (read from
the physics contacts). So an image is zero when the finger touches nothing and grows deeper and
wider with more force, and the pressed key's edges show in it.

The keys are boxes, so each ray is cast exactly with a slab test in the key's own frame (pure
NumPy). Tests check it against PyBullet's own ray casts (``rayTestBatch``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pianobot.sim.hand import FingerGeometry
from pianobot.sim.keyboard import KeyBox


@dataclass(frozen=True)
class TactileConfig:
    """Gel, image and sensitivity of the fingertip sensors."""

    rows: int = 60
    cols: int = 80
    gel_length: float = 0.015
    """Gel extent along the image rows (m); DIGIT's 20 x 30 mm gel scaled to the narrower fingertip."""
    gel_width: float = 0.020
    """Gel extent along the image columns (m), across the finger."""
    stiffness: float = 2000.0
    """Gel stiffness (N/m): 2 N of contact force squeezes it by 1 mm."""
    max_depth: float = 0.002
    """Depth (m) that maps to 1.0 in the image."""
    pad_tilt: float = 0.2
    """Angle (rad) by which the gel's normal leans from the fingertip's end towards its pad."""


class TactileRenderer:
    """Renders one depth image per fingertip from sensor poses, key angles and contact forces."""

    def __init__(self, config: TactileConfig, finger: FingerGeometry, boxes: list[KeyBox]):
        self.config = config
        self.boxes = boxes
        # sensor frame in the distal link's frame: origin at the tip sphere's centre
        self.origin_local = np.array([0.0, -(finger.distal - finger.tip_radius), 0.0])
        tilt = config.pad_tilt
        self.normal_local = np.array([0.0, -math.cos(tilt), -math.sin(tilt)])
        self.u_local = np.array([1.0, 0.0, 0.0])  # across the finger: image columns
        self.v_local = np.cross(self.normal_local, self.u_local)  # along the finger: image rows
        u = (np.arange(config.cols) + 0.5) / config.cols * config.gel_width - config.gel_width / 2
        v = (np.arange(config.rows) + 0.5) / config.rows * config.gel_length - config.gel_length / 2
        self.grid_v, self.grid_u = np.meshgrid(v, u, indexing="ij")  # (rows, cols)
        inside = 1.0 - (self.grid_u / (config.gel_width / 2)) ** 2 - (self.grid_v / (config.gel_length / 2)) ** 2
        self.gel = finger.tip_radius * np.sqrt(np.clip(inside, 0.0, None))  # dome height over the plane
        self.on_gel = inside > 0
        self.reach = math.hypot(config.gel_width, config.gel_length) / 2 + finger.tip_radius
        self.centers = np.array([b.center for b in boxes])
        self.halves = np.array([b.half for b in boxes])

    def rays(self, position: np.ndarray, rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World ray origins (rows*cols, 3) on the sensor plane and the shared direction (3,)."""
        origin = position + rotation @ self.origin_local
        u, v = rotation @ self.u_local, rotation @ self.v_local
        points = origin + self.grid_u.reshape(-1, 1) * u + self.grid_v.reshape(-1, 1) * v
        return points, rotation @ self.normal_local

    def _to_key_frames(self, points: np.ndarray, angles: np.ndarray) -> np.ndarray:
        """Points (..., 3) in world -> (K, ..., 3) in the rest frames of K keys with these angles.

        A key's joint turns it by -angle about x through its hinge (x_k, 0, 0); turning the
        points by +angle undoes that. x stays as it is (the boxes keep world x)."""
        c, s = np.cos(angles), np.sin(angles)
        shape = (len(angles),) + (1,) * (points.ndim - 1)
        y, z = points[..., 1], points[..., 2]
        out = np.empty((len(angles),) + points.shape)
        out[..., 0] = points[..., 0]
        out[..., 1] = c.reshape(shape) * y - s.reshape(shape) * z
        out[..., 2] = s.reshape(shape) * y + c.reshape(shape) * z
        return out

    def distances(self, position: np.ndarray, rotation: np.ndarray, key_angles: np.ndarray, max_range: float) -> np.ndarray:
        """Distance along the gel normal from each pixel to the nearest key (inf where none within range)."""
        rows, cols = self.config.rows, self.config.cols
        centre = position + rotation @ self.origin_local
        # keys whose box lies within reach of the gel at all
        local_centre = self._to_key_frames(centre[None, :], key_angles)[:, 0, :]
        gap = np.linalg.norm(np.maximum(np.abs(local_centre - self.centers) - self.halves, 0.0), axis=1)
        near = np.flatnonzero(gap < self.reach + max_range)
        if near.size == 0:
            return np.full((rows, cols), np.inf)
        points, direction = self.rays(position, rotation)
        angles = key_angles[near]
        local = self._to_key_frames(points, angles)  # (K, N, 3)
        d = self._to_key_frames(direction[None, :], angles)[:, 0, :]  # (K, 3)
        lo = (self.centers[near] - self.halves[near])[:, None, :]
        hi = (self.centers[near] + self.halves[near])[:, None, :]
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = (1.0 / d)[:, None, :]
            t1 = (lo - local) * inv
            t2 = (hi - local) * inv
        t_near = np.nanmax(np.minimum(t1, t2), axis=2)  # (K, N)
        t_far = np.nanmin(np.maximum(t1, t2), axis=2)
        hit = (t_far >= np.maximum(t_near, 0.0)) & (t_near <= max_range)
        t = np.where(hit, np.maximum(t_near, 0.0), np.inf)  # a ray starting inside a box hits at once
        return t.min(axis=0).reshape(rows, cols)

    def image(self, position: np.ndarray, rotation: np.ndarray, key_angles: np.ndarray, force: float) -> np.ndarray:
        """Depth image in [0, 1], float32, shape (rows, cols)."""
        cfg = self.config
        squeeze = min(force / cfg.stiffness, cfg.max_depth)
        distance = self.distances(position, rotation, key_angles, max_range=float(self.gel.max()) + squeeze + 1e-4)
        depth = np.where(self.on_gel, self.gel + squeeze - distance, 0.0)
        return (np.clip(depth, 0.0, cfg.max_depth) / cfg.max_depth).astype(np.float32)


def pool(images: np.ndarray, rows: int, cols: int) -> np.ndarray:
    """Average-pool the last two axes down to (rows, cols); they must divide the image size."""
    *lead, h, w = images.shape
    if h % rows or w % cols:
        raise ValueError(f"cannot pool {h}x{w} images to {rows}x{cols}: the sizes must divide")
    return images.reshape(*lead, rows, h // rows, cols, w // cols).mean(axis=(-3, -1))


def to_uint8(images: np.ndarray) -> np.ndarray:
    return np.rint(np.clip(images, 0.0, 1.0) * 255).astype(np.uint8)
