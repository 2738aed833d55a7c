"""Pixel checks on screenshots saved by session.shot (numpy only)."""

import numpy as np


def crop(image: np.ndarray, rect) -> np.ndarray:
    """The pixels inside a window rectangle (x0, y0, x1, y1); rows are bottom-up like the image."""
    x0, y0, x1, y1 = (int(round(v)) for v in rect)
    return image[max(0, y0):max(0, y1), max(0, x0):max(0, x1), :3]


def count_near(pixels: np.ndarray, color, tolerance: float = 0.06) -> int:
    """How many pixels lie within ``tolerance`` (per channel) of an RGB(A) display colour."""
    target = np.asarray(color[:3], dtype=np.float32)
    return int(np.all(np.abs(pixels - target) <= tolerance, axis=-1).sum())


def count_on_ramp(pixels: np.ndarray, ramp: np.ndarray, tolerance: float = 0.05, min_saturation: float = 0.35) -> int:
    """How many saturated pixels lie within ``tolerance`` of any colour of ``ramp`` (k, 3+)."""
    flat = pixels.reshape(-1, 3)
    saturation = flat.max(axis=1) - flat.min(axis=1)
    flat = flat[saturation >= min_saturation]
    if len(flat) == 0:
        return 0
    ramp = np.asarray(ramp, dtype=np.float32)[:, :3]
    distance = np.abs(flat[:, None, :] - ramp[None, :, :]).max(axis=2).min(axis=1)
    return int((distance <= tolerance).sum())


def outside(image: np.ndarray, inner, outer) -> np.ndarray:
    """Pixels of the ``outer`` rectangle that are not in ``inner`` (a flat (k, 3) array)."""
    x0, y0, x1, y1 = (int(round(v)) for v in outer)
    mask = np.zeros(image.shape[:2], dtype=bool)
    mask[max(0, y0):y1, max(0, x0):x1] = True
    a0, b0, a1, b1 = (int(round(v)) for v in inner)
    mask[max(0, b0):b1, max(0, a0):a1] = False
    return image[mask][:, :3]
