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

from pianobot.config import check_ranges
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

    def __post_init__(self) -> None:
        check_ranges(
            self,
            rows=(1, 512),
            cols=(1, 512),
            gel_length=(1e-4, 0.1),
            gel_width=(1e-4, 0.1),
            stiffness=(1e-3, 1e7),
            max_depth=(1e-5, 0.1),
            pad_tilt=(-1.6, 1.6),
        )


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
        self.gel_index = np.flatnonzero(self.on_gel.ravel())
        self.gel_uv = np.stack([self.grid_u.ravel()[self.gel_index], self.grid_v.ravel()[self.gel_index]], axis=1)
        self.plane_radius = math.hypot(config.gel_width, config.gel_length) / 2
        """Every ray starts within this distance of the tip sphere's centre."""
        self.gel_radius = max(config.gel_width / 2, config.gel_length / 2, finger.tip_radius)
        """Every point of the gel lies within this distance of the tip sphere's centre."""
        self.centers = np.array([b.center for b in boxes])
        self.halves = np.array([b.half for b in boxes])

    def rays(self, position: np.ndarray, rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World ray origins (rows*cols, 3) on the sensor plane and the shared direction (3,)."""
        origin = position + rotation @ self.origin_local
        u, v = rotation @ self.u_local, rotation @ self.v_local
        points = origin + self.grid_u.reshape(-1, 1) * u + self.grid_v.reshape(-1, 1) * v
        return points, rotation @ self.normal_local

    @staticmethod
    def _turn(y: np.ndarray, z: np.ndarray, angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(y, z) in the rest frames of keys turned by ``angles``: shapes (N,) -> (K, N).

        A key's joint turns it by -angle about x through its hinge (x_k, 0, 0); turning the
        points by +angle undoes that. x is the same in every key's frame."""
        c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
        return c * y - s * z, s * y + c * z

    def gaps(self, point: np.ndarray, key_angles: np.ndarray) -> np.ndarray:
        """Distance (m) from a world point to each key's box."""
        y, z = self._turn(np.array([point[1]]), np.array([point[2]]), key_angles)
        local = np.stack([np.full(len(key_angles), point[0]), y[:, 0], z[:, 0]], axis=1)
        return np.linalg.norm(np.maximum(np.abs(local - self.centers) - self.halves, 0.0), axis=1)

    def distances(
        self, position: np.ndarray, rotation: np.ndarray, key_angles: np.ndarray, max_range: float
    ) -> np.ndarray:
        """Distance along the gel normal from each gel pixel to the nearest key (inf where none within range)."""
        rows, cols = self.config.rows, self.config.cols
        out = np.full(rows * cols, np.inf, dtype=np.float32)
        centre = position + rotation @ self.origin_local
        near = np.flatnonzero(self.gaps(centre, key_angles) < self.plane_radius + max_range)
        if near.size == 0:
            return out.reshape(rows, cols)
        u, v, normal = rotation @ self.u_local, rotation @ self.v_local, rotation @ self.normal_local
        points = (centre + self.gel_uv @ np.stack([u, v])).astype(np.float32)  # (N, 3), gel pixels only
        angles = key_angles[near]
        y, z = self._turn(points[:, 1], points[:, 2], angles)  # (K, N)
        dy, dz = self._turn(np.array([normal[1]]), np.array([normal[2]]), angles)  # (K, 1)
        lo, hi = self.centers[near] - self.halves[near], self.centers[near] + self.halves[near]
        t_near = np.zeros((len(near), len(points)), dtype=np.float32)
        t_far = np.full_like(t_near, np.inf)
        for axis, coordinate, direction in (
            (0, points[None, :, 0], np.full((len(near), 1), normal[0])),
            (1, y, dy),
            (2, z, dz),
        ):
            direction = np.where(np.abs(direction) < 1e-12, 1e-12, direction)  # parallel to a face: no NaNs
            inverse = (1.0 / direction).astype(np.float32)
            t1 = (lo[:, axis : axis + 1] - coordinate) * inverse
            t2 = (hi[:, axis : axis + 1] - coordinate) * inverse
            np.maximum(t_near, np.minimum(t1, t2), out=t_near)  # t_near starts at 0: a ray starting inside hits at once
            np.minimum(t_far, np.maximum(t1, t2), out=t_far)
        hit = (t_far >= t_near) & (t_near <= max_range)
        out[self.gel_index] = np.where(hit, t_near, np.inf).min(axis=0)
        return out.reshape(rows, cols)

    def image(self, position: np.ndarray, rotation: np.ndarray, key_angles: np.ndarray, force: float) -> np.ndarray:
        """Depth image in [0, 1], float32, shape (rows, cols)."""
        cfg = self.config
        squeeze = min(force / cfg.stiffness, cfg.max_depth)
        centre = position + rotation @ self.origin_local
        if self.gaps(centre, key_angles).min() > self.gel_radius + squeeze:
            return np.zeros((cfg.rows, cfg.cols), np.float32)  # no key near the gel: nothing to see
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
