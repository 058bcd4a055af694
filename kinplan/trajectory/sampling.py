"""How sampled motions are checked: the check step of a motion, its joint speeds, and the
motion between its samples.

A motion is checked at its samples, so it must have enough of them: one shorter than
:data:`MIN_INTERVALS` sampling periods is checked at duration / MIN_INTERVALS (a 1 ms move is
not checked at its two resting ends only; the samples returned stay the caller's). Between two
samples a joint moves at its mean speed |Δq| / Δt at least somewhere, so that counts as a speed
of the sample that ends the interval along with the rates q̇ themselves (:func:`joint_speeds`).
Between the samples the motion played is the quintic Hermite through (q, q̇, q̈):
:func:`hermite_between` evaluates it inside every interval, :func:`hermite_peaks` finds its
extremes.
"""

from __future__ import annotations

import numpy as np

from kinplan.trajectory._profiles import quintic_coefficients

#: Fewest sampling intervals of a motion (joint or Cartesian).
MIN_INTERVALS = 16


def motion_step(duration: float, dt: float) -> float:
    """Sampling step [s] of a motion of ``duration`` [s] at the requested period ``dt`` [s]:
    ``dt``, or duration / :data:`MIN_INTERVALS` when that is smaller (and the duration > 0)."""
    return min(dt, duration / MIN_INTERVALS) if duration > 0 else dt


def joint_speeds(q: np.ndarray, qd: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Joint speeds (N, nq) [rad/s or m/s] of a sampled motion: at sample k the larger of
    |q̇_k| and the mean speed |q_k − q_(k−1)| / (t_k − t_(k−1)) of the interval ending there.

    Args:
        q: Joint positions (N, nq).
        qd: Joint velocities (N, nq).
        t: Sample times (N,) [s], increasing.
    """
    speeds = np.abs(qd)
    if len(t) > 1:
        mean = np.abs(np.diff(q, axis=0)) / np.diff(t)[:, None]
        speeds[1:] = np.maximum(speeds[1:], mean)
    return speeds


def hermite_between(
    t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, fractions: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The quintic Hermite interpolant of samples (exact in q, q̇ and q̈ at every sample: the
    motion viewers and exports play between the samples) inside every interval.

    Args:
        t: Sample times (N,) [s], increasing, N ≥ 2.
        q, qd, qdd: Positions, velocities, accelerations at the samples (N, n).
        fractions: Where to evaluate inside each interval, (F,) in [0, 1].

    Returns:
        (times, q, q̇, q̈): times (N−1, F) [s] and the interpolant's values (N−1, F, n).
    """
    h = np.diff(t)  # (N−1,)
    q0, q1, v0, v1, a0, a1 = q[:-1], q[1:], qd[:-1], qd[1:], qdd[:-1], qdd[1:]
    # the one quintic of the profiles (coefficients of τ^0..τ^5 per interval and joint)
    c0, c1, c2, c3, c4, c5 = np.moveaxis(
        quintic_coefficients(q0, q1, v0, v1, a0, a1, h[:, None]), 1, 0
    )
    tau = h[:, None] * np.asarray(fractions, dtype=float)[None, :]  # (N−1, F)
    x = tau[:, :, None]
    c0, c1, c2 = c0[:, None, :], c1[:, None, :], c2[:, None, :]
    c3, c4, c5 = c3[:, None, :], c4[:, None, :], c5[:, None, :]
    position = c0 + x * (c1 + x * (c2 + x * (c3 + x * (c4 + x * c5))))
    velocity = c1 + x * (2.0 * c2 + x * (3.0 * c3 + x * (4.0 * c4 + x * 5.0 * c5)))
    acceleration = 2.0 * c2 + x * (6.0 * c3 + x * (12.0 * c4 + x * 20.0 * c5))
    return t[:-1, None] + tau, position, velocity, acceleration


def hermite_peaks(
    t: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    limits: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The extremes of the quintic Hermite interpolant inside every interval, for its position,
    velocity and acceleration: (lowest q, highest q, largest |q̇|, largest |q̈|), each (N−1, n).

    Each is a polynomial per interval and joint; its extremes lie at the interval's ends or where
    its derivative vanishes: the derivative's real roots in the interval (eigenvalues of its
    companion matrices, all intervals and joints at once, in the interval's unit time), polished
    by two Newton steps, where the polynomial is evaluated.

    With ``limits`` (lower, upper, speed, acceleration limits, each (n,), inf where none) only
    the extremes that could reach a limit are solved for: elsewhere the values at nine points of
    the interval are returned, which a bound on the polynomial's curvature keeps within the
    limits (the extremes are then exact wherever they matter, and fast everywhere).

    Args:
        t: Sample times (N,) [s], increasing, N ≥ 2.
        q, qd, qdd: Positions, velocities, accelerations at the samples (N, n).
        limits: Optional (lower, upper, speed, acceleration) limits of the joints.
    """
    h = np.diff(t)[:, None]
    # q(x) over x = τ / h ∈ [0, 1]: the profiles' quintic, its τ^k coefficient times h^k
    c = quintic_coefficients(q[:-1], q[1:], qd[:-1], qd[1:], qdd[:-1], qdd[1:], h)
    position = np.moveaxis(c, 1, -1) * h[:, :, None] ** np.arange(6)  # (N−1, n, 6)
    powers = np.arange(6)
    velocity = (position * powers)[..., 1:]  # d/dx
    acceleration = (velocity * powers[:5])[..., 1:]
    jerk = (acceleration * powers[:4])[..., 1:]
    snap = (jerk * powers[:3])[..., 1:]

    def value(c: np.ndarray, x: np.ndarray) -> np.ndarray:
        out = np.zeros(np.broadcast_shapes(c.shape[:-1], x.shape))
        for k in range(c.shape[-1] - 1, -1, -1):
            out = out * x + c[..., k]
        return out

    def critical(dp: np.ndarray, ddp: np.ndarray) -> np.ndarray:
        """Real roots of dp in [0, 1] (…, m); others (complex, outside) as 0 (an end)."""
        m = dp.shape[-1] - 1
        lead = dp[..., m]
        size = np.abs(dp).max(axis=-1)
        tiny = np.abs(lead) <= 1e-13 * size
        lead = np.where(tiny, np.where(lead < 0, -1.0, 1.0) * 1e-13 * (size + 1e-300), lead)
        companion = np.zeros(dp.shape[:-1] + (m, m))
        companion[..., np.arange(1, m), np.arange(m - 1)] = 1.0
        companion[..., :, m - 1] = -dp[..., :m] / lead[..., None]
        roots = np.linalg.eigvals(companion)
        real = np.abs(roots.imag) <= 1e-6 * (1.0 + np.abs(roots.real))
        x = np.where(real, np.clip(roots.real, 0.0, 1.0), 0.0)
        for _ in range(2):  # Newton polish (a root of dp: an extreme of p)
            f, df = value(dp[..., None, :], x), value(ddp[..., None, :], x)
            step = np.divide(f, df, out=np.zeros_like(f), where=np.abs(df) > 0)
            x = np.clip(x - step, 0.0, 1.0)
        return x

    grid = np.linspace(0.0, 1.0, 9)

    def extremes(
        p: np.ndarray, dp: np.ndarray, ddp: np.ndarray, low: np.ndarray, high: np.ndarray
    ) -> tuple[np.ndarray, ...]:
        """(min, max) of p over x ∈ [0, 1]; solved exactly where [min, max] sampled, widened by
        the curvature bound (1/8)² / 8 · Σ|p''|, leaves [low, high]."""
        sampled = p @ (grid[None, :] ** np.arange(p.shape[-1])[:, None])  # (…, 9) at once
        lo, hi = sampled.min(axis=-1), sampled.max(axis=-1)
        slack = np.abs(ddp).sum(axis=-1) / 512.0
        near = (lo - slack < low) | (hi + slack > high) if limits is not None else lo <= np.inf
        if near.any():
            i, j = np.nonzero(near)
            inside = value(p[i, j][:, None, :], critical(dp[i, j], ddp[i, j]))
            lo[i, j] = np.minimum(lo[i, j], inside.min(axis=-1))
            hi[i, j] = np.maximum(hi[i, j], inside.max(axis=-1))
        return lo, hi

    if limits is None:
        every = np.full(q[1:].shape, np.inf)
        lower, upper, speed, accel = -every, every, every, every
    else:
        lower, upper = limits[0] + 0.0 * h, limits[1] + 0.0 * h
        speed, accel = limits[2] * h, limits[3] * h**2  # in the unit time x
        lower, upper = np.where(np.isfinite(lower), lower, -np.inf), upper
    q_lo, q_hi = extremes(position, velocity, acceleration, lower, upper)
    v_lo, v_hi = extremes(velocity, acceleration, jerk, -speed, speed)
    a_lo, a_hi = extremes(acceleration, jerk, snap, -accel, accel)
    return q_lo, q_hi, np.maximum(-v_lo, v_hi) / h, np.maximum(-a_lo, a_hi) / h**2
