"""Constants of the GRACE-A/B study (issue 20): the data's provenance, the Earth model, and every choice.

The data are real (:mod:`.dataset`); the Earth constants are the standard ones
(EGM96/WGS-84 values); every noise level and tuning below is a *choice* of
this study, said so where it is defined. Nothing here is a result.
"""

__all__ = [
    "CITATION",
    "DATA_FILES",
    "OMEGA_EARTH",
    "MU_EARTH",
    "R_EARTH_M",
    "J2",
    "DT_S",
    "TRUTH_SIGMA_M",
    "KBAND_TOLERANCE_M",
    "ANGLE_SIGMA_RAD",
    "GNSS_SIGMA_M",
    "OUTLIER_FRACTION",
    "OUTLIER_SCALE",
    "DROPOUT_FRACTION",
    "HORIZONS",
]

CITATION = (
    "GRACE-A/B formation, 27 July 2010 (day 208): precise orbits (Bernese GNSS 5.2, CODE) and the K-band "
    "inter-satellite range, from the LEOGPS project (S. Low, github.com/sammmlow/LEOGPS, commit fc5e4e1, "
    "folder reference/), MIT licence"
)

#: The vendored files (gzip), in ``hinfnav/papers/grace2010/data/``.
DATA_FILES = {"A": "grca_truth.csv.gz", "B": "grcb_truth.csv.gz", "kband": "grc_kb_rng.csv.gz"}

#: Earth rotation rate, rad/s (IERS conventional value, mean sidereal rate).
OMEGA_EARTH = 7.292115e-5
#: Earth gravitational parameter, m³/s² (EGM96 / WGS-84).
MU_EARTH = 3.986004418e14
#: Earth equatorial radius, m (WGS-84).
R_EARTH_M = 6378137.0
#: Second zonal harmonic (unnormalised), EGM96.
J2 = 1.08262668e-3

#: Sampling interval of the data, s.
DT_S = 10.0

#: The POD truth's own 1σ uncertainty per satellite axis, m (the issue's "≈ 2 cm"; CODE's GRACE
#: reduced-dynamic orbits are validated at the 2 cm level by SLR and K-band). Marked on the figures.
TRUTH_SIGMA_M = 0.02
#: The K-band check of the issue: |r_A − r_B| − K-band range within this, m, at every epoch.
KBAND_TOLERANCE_M = 0.04

#: Choice: 1σ of the simulated line-of-sight azimuth and elevation, rad. 10 µrad is a good star-tracker-
#: class camera; at 227 km it is 2.3 m across the line of sight.
ANGLE_SIGMA_RAD = 1.0e-5
#: Choice: 1σ of the simulated relative GNSS position per Hill axis, m (code-differential GPS between
#: two LEO receivers, the level LEOGPS itself reaches without carrier-phase ambiguity fixing).
GNSS_SIGMA_M = 1.0
#: Choice: fraction of epochs whose measurement is an outlier, and the outlier's size in σ.
OUTLIER_FRACTION = 0.02
OUTLIER_SCALE = 30.0
#: Choice: fraction of epochs with no measurement (dropouts), in blocks (see :mod:`.measurements`).
DROPOUT_FRACTION = 0.2

#: Propagation horizons of the mismatch study, as fractions of GRACE-B's orbital period.
HORIZONS = {"tenth_orbit": 0.1, "quarter_orbit": 0.25, "one_orbit": 1.0}
