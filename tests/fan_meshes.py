"""Fans of slivers around vertices of very high valence (issue 39, "no slow corner"), as
(vertices, triangles) arrays: a double cone, a UV sphere's poles, a disc fanned from its centre,
a cylinder whose caps are fans. Shared by tests/python/test_high_valence.py and
tests/bench/bench_high_valence.py."""

import numpy as np


def cone(n):
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    P = np.vstack([np.c_[np.cos(a), np.sin(a), np.zeros(n)], [0, 0, 1], [0, 0, -1]])
    i = np.arange(n); j = (i + 1) % n
    return P, np.vstack([np.c_[i, j, np.full(n, n)], np.c_[j, i, np.full(n, n + 1)]])


def uv_sphere(segments, rings=50):
    # rings - 1 circles of `segments` vertices between two poles
    theta = np.pi * np.arange(1, rings) / rings
    a = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    P = np.vstack([np.c_[np.outer(np.sin(theta), np.cos(a)).ravel(), np.outer(np.sin(theta), np.sin(a)).ravel(),
                         np.repeat(np.cos(theta), segments)], [0, 0, 1], [0, 0, -1]])
    s = np.arange(segments); t = (s + 1) % segments
    top, bottom = len(P) - 2, len(P) - 1
    T = [np.c_[s, t, np.full(segments, top)]]
    for r in range(rings - 2):
        a0, b0 = r * segments + s, r * segments + t
        a1, b1 = a0 + segments, b0 + segments
        T += [np.c_[a0, a1, b0], np.c_[b0, a1, b1]]
    last = (rings - 2) * segments
    T.append(np.c_[last + s, np.full(segments, bottom), last + t])
    return P, np.vstack(T)


def fan_disc(n):
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    P = np.vstack([np.c_[np.cos(a), np.sin(a), np.zeros(n)], [0, 0, 0]])
    i = np.arange(n)
    return P, np.c_[i, (i + 1) % n, np.full(n, n)]


def cylinder_caps(segments, rows=4):
    a = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    z = np.linspace(0, 1, rows + 1)
    P = np.vstack([np.c_[np.tile(np.cos(a), rows + 1), np.tile(np.sin(a), rows + 1), np.repeat(z, segments)],
                   [0, 0, 0], [0, 0, 1]])
    s = np.arange(segments); t = (s + 1) % segments
    T = []
    for r in range(rows):
        a0, b0 = r * segments + s, r * segments + t
        T += [np.c_[a0, b0, a0 + segments], np.c_[b0, b0 + segments, a0 + segments]]
    low, high = len(P) - 2, len(P) - 1
    T += [np.c_[t, s, np.full(segments, low)], np.c_[rows * segments + s, rows * segments + t, np.full(segments, high)]]
    return P, np.vstack(T)
