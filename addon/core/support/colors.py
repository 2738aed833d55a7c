"""Colours of the viewport overlays and the error visualisation (no Blender needed).

Overlay colours follow the thesis' figures (4.5-4.9): handle loops yellow, tunnel loops
turquoise, generator edges pink, boundary vertices red. Errors are coloured on a five-stop
ramp from blue (no error) over cyan, green and yellow to red (the largest error on the
scale), so both ends read clearly on a grey viewport. Cluster regions (thesis fig. 4.1) get
pastel colours that stay apart from all of these; faces whose three corners lie in three
clusters (the faces that become output triangles) are drawn red, faces on a border between
two clusters dark blue.

All colours are display (sRGB) RGBA values in [0, 1], as the ``gpu`` module draws them.
"""

from __future__ import annotations

import numpy as np

HANDLE = (1.0, 1.0, 0.0, 1.0)              #: yellow
TUNNEL = (0.25, 0.88, 0.82, 1.0)           #: turquoise
GENERATOR = (1.0, 0.41, 0.71, 1.0)         #: pink
BOUNDARY = (1.0, 0.0, 0.0, 1.0)            #: red
NONMANIFOLD = (1.0, 0.5, 0.0, 1.0)         #: orange: edges with 3+ triangles, pinched vertices
SAMPLE = (0.0, 0.25, 1.0, 1.0)             #: deep blue
CLEAN_REMOVE = (0.1, 1.0, 0.25, 1.0)       #: green: a loop or hole the clean-up will remove (preview)
CLEAN_LEAVE = (0.75, 0.35, 1.0, 1.0)       #: violet: one it will leave (above the size, or not removable)
CLUSTER_BORDER = (0.12, 0.16, 0.45, 1.0)   #: dark blue: faces on a border of two clusters
CLUSTER_CORNER = (0.9, 0.1, 0.1, 1.0)      #: red: faces whose corners lie in three clusters

#: (position on the scale, RGB): blue, cyan, green, yellow, red.
ERROR_RAMP = (
    (0.00, (0.16, 0.28, 0.92)),
    (0.25, (0.10, 0.74, 0.92)),
    (0.50, (0.20, 0.82, 0.24)),
    (0.75, (1.00, 0.84, 0.10)),
    (1.00, (0.90, 0.10, 0.10)),
)


def error_colors(values, scale: float, alpha: float = 1.0) -> np.ndarray:
    """RGBA (n, 4) float32 colours of ``values`` on the ramp from 0 to ``scale``.

    Values at or above ``scale`` are red; NaN (an element with no measured error) is grey.
    A non-positive ``scale`` maps every finite value to blue.
    """
    values = np.asarray(values, dtype=np.float64).reshape(-1)
    t = np.clip(values / scale, 0.0, 1.0) if scale > 0 else np.zeros_like(values)
    stops = np.array([s for s, _ in ERROR_RAMP])
    rgb = np.array([c for _, c in ERROR_RAMP])
    out = np.empty((len(values), 4), dtype=np.float32)
    for channel in range(3):
        out[:, channel] = np.interp(t, stops, rgb[:, channel])
    out[:, 3] = alpha
    out[~np.isfinite(values)] = (0.5, 0.5, 0.5, alpha)
    return out


def legend_ticks(scale: float, diagonal: float, count: int = 5) -> list[tuple[float, str]]:
    """``count`` labels for the error legend: (position in [0, 1], text).

    Each label gives the absolute distance and, when the diagonal is known, the percentage of
    the bounding-box diagonal, e.g. ``"0.0123 (0.52 %)"``.
    """
    ticks = []
    for i in range(count):
        t = i / (count - 1)
        value = t * scale
        text = f"{value:.3g}"
        if diagonal > 0:
            text += f" ({100.0 * value / diagonal:.3g} %)"
        ticks.append((t, text))
    return ticks


def _hsv_to_rgb(h: np.ndarray, s: float, v: float) -> np.ndarray:
    i = np.floor(h * 6.0).astype(int) % 6
    f = h * 6.0 - np.floor(h * 6.0)
    p, q, t = v * (1 - s), v * (1 - f * s), v * (1 - (1 - f) * s)
    table = np.stack([np.stack([np.full_like(f, v), t, np.full_like(f, p)], -1),
                      np.stack([q, np.full_like(f, v), np.full_like(f, p)], -1),
                      np.stack([np.full_like(f, p), np.full_like(f, v), t], -1),
                      np.stack([np.full_like(f, p), q, np.full_like(f, v)], -1),
                      np.stack([t, np.full_like(f, p), np.full_like(f, v)], -1),
                      np.stack([np.full_like(f, v), np.full_like(f, p), q], -1)], 0)
    return table[i, np.arange(len(h))]


def cluster_colors(labels) -> np.ndarray:
    """A pastel RGBA (n, 4) float32 colour per cluster label; neighbouring ids differ in hue.

    Hues step by the golden ratio, so clusters with close ids (which the flood fill tends to
    put next to each other) still look different. Label -1 (no cluster) is mid grey.
    """
    labels = np.asarray(labels, dtype=np.int64).reshape(-1)
    hue = np.mod(labels * 0.6180339887498949, 1.0)
    out = np.empty((len(labels), 4), dtype=np.float32)
    out[:, :3] = _hsv_to_rgb(hue, 0.35, 0.95)
    out[:, 3] = 1.0
    out[labels < 0] = (0.5, 0.5, 0.5, 1.0)
    return out


def cluster_face_colors(triangles, labels) -> np.ndarray:
    """Colour of every input triangle in the clustering view (thesis fig. 4.1).

    A triangle inside one cluster takes that cluster's colour, one spanning two clusters is
    dark blue, one spanning three is red (it becomes an output triangle).
    """
    triangles = np.asarray(triangles)
    corner_labels = np.asarray(labels)[triangles]
    a, b, c = corner_labels[:, 0], corner_labels[:, 1], corner_labels[:, 2]
    distinct = 1 + (a != b).astype(int) + ((c != a) & (c != b)).astype(int)
    out = cluster_colors(a)
    out[distinct == 2] = CLUSTER_BORDER
    out[distinct == 3] = CLUSTER_CORNER
    return out


__all__ = ["BOUNDARY", "CLUSTER_BORDER", "CLUSTER_CORNER", "ERROR_RAMP", "GENERATOR", "HANDLE", "NONMANIFOLD",
           "SAMPLE", "TUNNEL", "cluster_colors", "cluster_face_colors", "error_colors", "legend_ticks"]
