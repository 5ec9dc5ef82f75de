"""Active disturbance rejection control (ADRC) of a drag-free satellite, and the PID it is compared with.

* :func:`fal` — Han's power function ``fal(e, α, δ)``: ``e/δ^{1−α}`` for
  ``|e| ≤ δ``, ``|e|^α sign(e)`` beyond (Han 2008);
* :class:`NonlinearPID` — ``u₀ = k_p fal(e_p) + k_i fal(e_i) + k_d fal(e_d)``
  (the NLPID of Yang et al. 2020, Section 3) or its linear counterpart
  ``k_p e_p + k_i e_i + k_d e_d`` (the tuned PID of Fig 9), with the
  integral ``e_i`` read as printed (the sum of the errors over the steps),
  as ``h`` times that sum, or switched off;
* :class:`DragFreeADRC` — the laws (44)-(46) on the 27-state extended
  estimate: the NLPID outputs are decoupled and the estimated external
  disturbances and internal couplings are cancelled,

  .. math::

      T_{Csc} = I_{sc} T_{Csc0} - \\hat T_{Dsc}, \\quad
      F_{Csc} = -F_{Csc0} + m_{sc} \\hat h_{idf} - \\hat F_{Dsc}, \\quad
      T_{Ctm} = I_{tm} T_{Ctm0} - \\hat T_{Dtm} - I_{tm} \\hat h_{itm},

  with ``ĥ_idf = −(K_trans r̂ + D_trans ṙ̂)/m_tm`` and ``ĥ_itm = I_tm⁻¹(K_rot
  φ̂_rel + D_rot φ̂̇_rel)``; each input is then clipped to the cube
  ``|u_i| ≤ ρ`` (Remark 5). With ``dragfree_compensation=False`` the
  drag-free law is ``F_Csc = −F_Csc0`` alone: the PID comparison of Fig 9.

Everything acts on batches (rows are runs); the integrators are carried in
an explicit controller state.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.validation import as_choice, as_matrix, as_nonnegative, as_positive

__all__ = ["fal", "NonlinearPID", "DragFreeADRC", "saturate"]

#: Readings of the NLPID integral e_i: the printed sum over steps, h times it, none.
INTEGRALS = ("printed", "dt", "off")


def fal(e: ArrayLike, alpha: float = 0.5, delta: float = 0.01) -> NDArray[np.float64]:
    """Han's ``fal(e, α, δ)``: linear with slope ``δ^{α−1}`` inside ``|e| ≤ δ``, ``|e|^α sign(e)`` outside.

    Parameters
    ----------
    e : array_like
    alpha : float
        Exponent, 0 < α ≤ 1.
    delta : float
        Width of the linear zone, > 0.

    Returns
    -------
    ndarray
        Continuous at ``|e| = δ``; odd in e.
    """
    alpha = as_positive("alpha", alpha)
    delta = as_positive("delta", delta)
    if alpha > 1:
        raise InputError(f"alpha must be in (0, 1]; got {alpha}")
    return _fal(np.asarray(e, dtype=float), alpha, delta)


def _fal(e, alpha, delta):
    ae = np.abs(e)
    inside = ae <= delta
    lin = e * delta ** (alpha - 1.0)
    if inside.all():  # the usual case in a settled loop: one product
        return lin
    return np.where(inside, lin, np.sign(e) * np.maximum(ae, delta) ** alpha)


def saturate(u: ArrayLike, bound: float) -> NDArray[np.float64]:
    """Clip every component to ``[−bound, bound]`` (the cube B(ρ) of Remark 5)."""
    return np.clip(u, -bound, bound)


class NonlinearPID:
    """``u₀ = k_p g(e_p) + k_i g(e_i) + k_d g(e_d)`` with ``g = fal(·, α, δ)`` (or ``g(e) = e``).

    Parameters
    ----------
    kp, ki, kd : float or array_like
        Gains per channel.
    alpha, delta : float
        fal's parameters (fal(e) ≡ fal(e, 0.5, 0.01) in the paper).
    integral : {"printed", "dt", "off"}
        ``e_i`` as printed, ``Σ_{j≤k} e_p,j`` (per step); ``dt``: ``h Σ e_p,j``;
        ``off``: no integral term.
    dt : float
        Step h, s (used by ``integral="dt"``).
    linear : bool
        Use ``g(e) = e`` (a linear PID) instead of fal.
    """

    def __init__(self, kp: ArrayLike, ki: ArrayLike, kd: ArrayLike, *, alpha: float = 0.5, delta: float = 0.01,
                 integral: str = "printed", dt: float = 0.1, linear: bool = False) -> None:
        self.kp, self.ki, self.kd = (np.asarray(v, dtype=float) for v in (kp, ki, kd))
        for name, v in (("kp", self.kp), ("ki", self.ki), ("kd", self.kd)):
            if not np.all(np.isfinite(v)) or np.any(v < 0):
                raise InputError(f"{name} must be finite and >= 0")
        self.alpha = as_positive("alpha", alpha)
        self.delta = as_positive("delta", delta)
        fal(0.0, self.alpha, self.delta)  # checks alpha <= 1
        self.integral = as_choice("integral reading", integral, INTEGRALS)
        self.dt = as_positive("dt", dt)
        self.linear = bool(linear)
        self._iscale = {"printed": 1.0, "dt": self.dt, "off": 0.0}[self.integral]

    def g(self, e: NDArray[np.float64]) -> NDArray[np.float64]:
        """fal(e, α, δ), or e for a linear PID."""
        return e if self.linear else _fal(e, self.alpha, self.delta)

    def __call__(self, e_p, e_d, e_i):
        """``(u₀, e_i')``: the output and the integral after adding this step's ``e_p``."""
        e_i = e_i + self._iscale * e_p
        u0 = self.kp * self.g(e_p) + self.kd * self.g(e_d)
        if self.integral != "off":
            u0 = u0 + self.ki * self.g(e_i)
        return u0, e_i


class DragFreeADRC:
    """The ADRC laws (44)-(46) on the extended estimate.

    The estimate is ``[φ_sc, φ̇_sc, T_Dsc, r, ṙ, F_Dsc, φ_rel, φ̇_rel, T_Dtm]`` (27, the order of (6)).

    Parameters
    ----------
    I_sc, I_tm : array_like, shape (3, 3)
        Inertias, kg·m².
    m_sc, m_tm : float
        Masses, kg.
    K_trans, D_trans, K_rot, D_rot : array_like, shape (3, 3)
        Couplings as they enter (2)-(3) (K_rot, D_rot with the sign used in the model).
    attitude, dragfree, relative : NonlinearPID
        The three loops' T_Csc0, F_Csc0, T_Ctm0.
    bound : float
        ρ: every input clipped to ``[−ρ, ρ]`` (N or N·m).
    dragfree_compensation : bool
        Cancel ``F̂_Dsc`` and ``ĥ_idf`` in (45) (ADRC); False gives ``F_Csc = −F_Csc0`` (the PID comparison).
    """

    n_state = 27
    n_input = 9

    def __init__(self, *, I_sc: ArrayLike, I_tm: ArrayLike, m_sc: float, m_tm: float, K_trans: ArrayLike,
                 D_trans: ArrayLike, K_rot: ArrayLike, D_rot: ArrayLike, attitude: NonlinearPID,
                 dragfree: NonlinearPID, relative: NonlinearPID, bound: float,
                 dragfree_compensation: bool = True) -> None:
        self.I_sc = as_matrix("I_sc", I_sc, (3, 3))
        self.I_tm = as_matrix("I_tm", I_tm, (3, 3))
        self.m_sc = as_positive("m_sc", m_sc)
        self.m_tm = as_positive("m_tm", m_tm)
        K_trans, D_trans = as_matrix("K_trans", K_trans, (3, 3)), as_matrix("D_trans", D_trans, (3, 3))
        K_rot, D_rot = as_matrix("K_rot", K_rot, (3, 3)), as_matrix("D_rot", D_rot, (3, 3))
        for name, law in (("attitude", attitude), ("dragfree", dragfree), ("relative", relative)):
            if not isinstance(law, NonlinearPID):
                raise InputError(f"{name} must be a NonlinearPID; got {type(law).__name__}")
        self.attitude, self.dragfree, self.relative = attitude, dragfree, relative
        self.bound = as_nonnegative("bound", bound)
        self.dragfree_compensation = bool(dragfree_compensation)
        # ĥ_idf m_sc = −(m_sc/m_tm)(K r + D v);   I_tm ĥ_itm = K_rot φ_rel + D_rot φ̇_rel
        self._h_idf = -(self.m_sc / self.m_tm) * np.hstack([K_trans, D_trans])  # acts on [r, v]
        self._h_itm = np.hstack([K_rot, D_rot])  # acts on [φ_rel, φ̇_rel]
        # the three loops stacked channel by channel: [attitude (3), drag-free (3), relative attitude (3)]
        loops = (attitude, dragfree, relative)
        def per(get):
            return np.concatenate([np.broadcast_to(np.asarray(get(law), dtype=float), (3,)) for law in loops])

        self._kp, self._ki, self._kd = per(lambda c: c.kp), per(lambda c: c.ki), per(lambda c: c.kd)
        self._ki = np.where(per(lambda c: c.integral == "off") > 0, 0.0, self._ki)
        self._iscale = per(lambda c: c._iscale)
        self._alpha, self._delta = per(lambda c: c.alpha), per(lambda c: c.delta)
        self._linear = per(lambda c: c.linear) > 0
        self._any_linear = bool(self._linear.any())
        self._slope = np.where(self._linear, 1.0, self._delta ** (self._alpha - 1.0))
        self._zone = float(np.min(np.where(self._linear, np.inf, self._delta)))  # all |e| below: g(e) = slope e
        self._has_i = bool(np.any(self._ki > 0))
        self._comp_rows = None  # per-row compensation of stacked laws (:meth:`stacked`)
        self._pos = np.r_[0:3, 9:12, 18:21]
        self._rate = np.r_[3:6, 12:15, 21:24]
        self._pos_rate = np.r_[self._pos, self._rate]

    def start(self, runs: int) -> NDArray[np.float64]:
        """Zero integrators e_i of the nine channels (attitude, drag-free, relative attitude): shape (runs, 9)."""
        return np.zeros((int(runs), 9))

    @classmethod
    def stacked(cls, laws: list[DragFreeADRC], runs: int) -> DragFreeADRC:
        """Several laws as one on stacked rows: rows ``v·runs … (v+1)·runs − 1`` follow ``laws[v]``.

        The laws must share the plant (inertias, masses, couplings) and the bound; their loop gains,
        integral readings and compensation may differ. Each row's input is the one its own law gives
        (the same arithmetic, element by element), computed in one call for all rows.
        """
        if not laws or not all(isinstance(law, cls) for law in laws):
            raise InputError("laws must be a non-empty list of DragFreeADRC")
        first = laws[0]
        for law in laws[1:]:
            if law.bound != first.bound or any(not np.array_equal(getattr(law, k), getattr(first, k))
                                               for k in ("I_sc", "I_tm", "_h_idf", "_h_itm")):
                raise InputError("stacked laws must share the plant (inertias, couplings) and the bound")
        out = cls.__new__(cls)
        out.__dict__.update(first.__dict__)
        runs = int(runs)
        rows = lambda name: np.repeat(np.stack([getattr(law, name) for law in laws]), runs, axis=0)
        for name in ("_kp", "_ki", "_kd", "_iscale", "_alpha", "_delta", "_linear", "_slope"):
            setattr(out, name, rows(name))
        out._any_linear = bool(out._linear.any())
        out._zone = min(law._zone for law in laws)
        out._has_i = any(law._has_i for law in laws)
        out._comp_rows = np.repeat([law.dragfree_compensation for law in laws], runs)
        out.dragfree_compensation = bool(out._comp_rows.any())
        return out

    def __call__(self, xhat, attitude_ref, state):
        """Inputs ``u = [T_Csc, F_Csc, T_Ctm]`` for a batch of estimates.

        Parameters
        ----------
        xhat : ndarray, shape (runs, 27)
        attitude_ref : ndarray, shape (3,) or (runs, 3)
            Commanded φ_sc, rad (the other loops regulate to zero).
        state : ndarray, shape (runs, 9)
            The integrals e_i, from :meth:`start` or the previous call.

        Returns
        -------
        u : ndarray, shape (runs, 9)
            Clipped to the actuator bounds.
        u_cmd : ndarray, shape (runs, 9)
            Before clipping.
        state : ndarray, shape (runs, 9)
        """
        xhat = np.asarray(xhat, dtype=float)
        if xhat.ndim != 2 or xhat.shape[1] != 27:
            raise InputError(f"xhat must have shape (runs, 27); got {xhat.shape}")
        runs = xhat.shape[0]
        # e = [e_p, e_d (, e_i)] as one (2 or 3, runs, 9) array: e_p = −x̂ of [φ_sc, r, φ_rel], e_d = −x̂ of the rates
        e = np.empty((3 if self._has_i else 2, runs, 9))
        np.negative(xhat[:, self._pos_rate].reshape(runs, 2, 9).swapaxes(0, 1), out=e[:2])
        e_p = e[0]
        e_p[:, 0:3] += attitude_ref
        e_i = state + self._iscale * e_p
        if self._has_i:
            e[2] = e_i
        g = self._g(e)
        u0 = self._kp * g[0] + self._kd * g[1]
        if self._has_i:
            u0 = u0 + self._ki * g[2]
        u = np.empty((runs, 9))
        u[:, 0:3] = u0[:, 0:3] @ self.I_sc.T - xhat[:, 6:9]
        if self._comp_rows is not None:  # stacked laws: compensation per row
            minus = -u0[:, 3:6]
            u[:, 3:6] = np.where(self._comp_rows[:, None], minus + xhat[:, 9:15] @ self._h_idf.T - xhat[:, 15:18], minus)
        elif self.dragfree_compensation:
            u[:, 3:6] = -u0[:, 3:6] + xhat[:, 9:15] @ self._h_idf.T - xhat[:, 15:18]
        else:
            u[:, 3:6] = -u0[:, 3:6]
        u[:, 6:9] = u0[:, 6:9] @ self.I_tm.T - xhat[:, 24:27] - xhat[:, 18:24] @ self._h_itm.T
        return u.clip(-self.bound, self.bound), u, e_i

    def _g(self, e):
        if np.abs(e).max() <= self._zone:  # fal's linear zone everywhere (the settled loop): one product
            return e * self._slope
        g = _fal(e, self._alpha, self._delta)
        return np.where(self._linear, e, g) if self._any_linear else g
