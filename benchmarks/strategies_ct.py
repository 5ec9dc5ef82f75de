"""Huber × sigma-point and strong tracking × sigma-point on a system none of the papers has.

A planar target in a constant turn (:class:`hinfnav.systems.ConstantTurn`, state (x, y, vx, vy, ω)) seen by a
range/bearing sensor at the origin (:class:`hinfnav.systems.RangeBearing`); the measurement noise is Gaussian,
or heavy-tailed with the SAME covariance R the filters are given (a unit-variance shape times D: the
ε-contaminated Gaussian (1−ε) N + ε N(0, r²) with ε = 0.1, r = 10, and Student-t with 5 degrees of freedom).
Every filter has the model's true Q and R and the package defaults (Huber γ = 1.345; strong tracking
ρ = 0.95, β = 1; maximum correntropy σ = 2): nothing is tuned. Reports the position RMSE (m) pooled over steps 20…n and over all runs, over the runs not lost (position error
below 1 km throughout), and the number of runs lost.

    python benchmarks/strategies_ct.py [--runs 100] [--steps 200] [--seed 0]
"""

import argparse

import numpy as np

from hinfnav.core.exceptions import HinfnavError
from hinfnav.estimators import CorrentropyFilter, ExtendedKalmanFilter, HuberFilter, SigmaPointFilter, StrongTrackingEKF
from hinfnav.estimators.strategies import compose
from hinfnav.noise import GaussianNoise, MixtureNoise, StudentTNoise
from hinfnav.systems import ConstantTurn, RangeBearing

DT, SIGMA_A, SIGMA_W = 1.0, 0.5, 1e-3  # s, m/s², rad/s per step
SIGMA_R, SIGMA_B = 10.0, 0.01  # m, rad
X0 = np.array([1000.0, 2000.0, 10.0, -5.0, 0.02])  # m, m, m/s, m/s, rad/s
P0 = np.diag([100.0, 100.0, 10.0, 10.0, 0.05]) ** 2
NOISES = {"gaussian": GaussianNoise(), "contaminated (eps 0.1, ratio 10)": MixtureNoise(eps=0.1, ratio=10.0),
          "student-t (5 dof)": StudentTNoise(dof=5)}


def truth(system, meas, noise, runs, steps, rng):
    """States (runs, steps, 5) and readings (runs, steps, 2): w ~ N(0, Q), v = D · noise (unit variance)."""
    x = X0 + rng.standard_normal((runs, 5)) @ np.linalg.cholesky(P0).T
    G = np.zeros((5, 3))  # (CT2): w = [G_a a; σ_ω ξ], a ~ N(0, σ_a² I₂), ξ ~ N(0, 1): cov w = Q
    G[:4, :2] = SIGMA_A * np.array([[DT * DT / 2, 0.0], [0.0, DT * DT / 2], [DT, 0.0], [0.0, DT]])
    G[4, 2] = SIGMA_W
    D = np.diag([SIGMA_R, SIGMA_B])
    xs, ys = np.empty((runs, steps, 5)), np.empty((runs, steps, 2))
    for k in range(steps):
        xs[:, k] = x
        ys[:, k] = meas.function(x) + noise.sample(rng, (runs, 2)) @ D.T
        x = system.f(x) + rng.standard_normal((runs, 3)) @ G.T
    return xs, ys


def filters(system, meas):
    ekf = ExtendedKalmanFilter(system, meas, P0=P0)
    ukf = SigmaPointFilter(system, meas, P0=P0)
    return {"ekf": ekf, "hbf (Huber x EKF)": HuberFilter.from_ekf(ekf),
            "stekf (ST x EKF)": StrongTrackingEKF(system, meas, P0=P0), "mckf (MCC x EKF)": CorrentropyFilter.from_ekf(ekf),
            "ukf": ukf,
            "huber_ukf": compose(ukf, correction="huber"), "stukf": compose(ukf, fading="strong_tracking"),
            "mcc_ukf (MCC x UKF)": compose(ukf, correction="correntropy", name="mcc_ukf")}


#: A run whose position error exceeds this at any step after the first 20 is counted as lost, m.
LOST_M = 1000.0


def rmse(est, xs, ys, first):
    """``(RMSE over all runs, RMSE over the runs not lost, runs lost)``: pooled position RMSE, m (a run that
    stops with an error — FilterDivergedError, a singular matrix — counts as lost)."""
    runs = xs.shape[0]
    u = np.zeros(ys.shape[:2] + (0,))
    try:
        xhat = est.estimate(ys, u, X0, keep_covariance=False).xhat
        ok = np.ones(runs, dtype=bool)
    except (HinfnavError, np.linalg.LinAlgError):  # some run diverged or hit a singular matrix: run one by one
        xhat, ok = np.full(xs.shape, np.nan), np.zeros(runs, dtype=bool)
        for r in range(runs):
            try:
                xhat[r] = est.estimate(ys[r:r + 1], u[r:r + 1], X0, keep_covariance=False).xhat[0]
                ok[r] = np.isfinite(xhat[r]).all()
            except (HinfnavError, np.linalg.LinAlgError):
                pass
    err2 = np.sum((xhat - xs)[:, first:, :2] ** 2, axis=-1)
    kept = ok & (np.nanmax(err2, axis=1) < LOST_M**2)
    every = float(np.sqrt(np.mean(err2[ok]))) if ok.all() else float("nan")
    return every, float(np.sqrt(np.mean(err2[kept]))), int((~kept).sum())


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=100)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    system = ConstantTurn(DT, SIGMA_A, SIGMA_W)
    meas = RangeBearing(5, SIGMA_R, SIGMA_B)
    print(f"position RMSE (m), steps 20..{args.steps}, {args.runs} runs, seed {args.seed}: all runs / runs not lost "
          f"(error < {LOST_M:g} m throughout) [runs lost]")
    print(f"{'filter':20s}" + "".join(f"{name:>36s}" for name in NOISES))
    results = {}
    for i, noise in enumerate(NOISES.values()):
        xs, ys = truth(system, meas, noise, args.runs, args.steps, np.random.default_rng([args.seed, i]))
        for name, est in filters(system, meas).items():
            results.setdefault(name, []).append(rmse(est, xs, ys, 20))
    for name, row in results.items():
        print(f"{name:20s}" + "".join(f"{a:>14.4g} / {k:8.2f} [{d:3d}]".rjust(36) for a, k, d in row))


if __name__ == "__main__":
    main()
