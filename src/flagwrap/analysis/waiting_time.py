"""Waiting time law ``t_c / T = c eps^-beta`` (paper Eq. 3, Fig. 6) and the sweep that measures it.

Paper (main text, "Slow dynamics right above the onset of buckling"): with
``eps = (omega - omega_c) / omega_c``, the waiting time between the CCW -> CW switch and the
onset of the free end's rise follows ``t_c / T ~ 1 / eps``; Fig. 6 draws ``0.5 / eps``
(``beta = 1``, ``c ~= 0.5``), and ``t_c / T < 1`` for ``omega / omega_c > 2``.

Fit
---
:class:`PowerLawFit` fits ``log t = log c - beta log eps`` by (weighted) linear least squares
(:func:`scipy.optimize.curve_fit`). Multiplicative scatter of ``t_c`` is additive in log
space, which is the natural noise model for a detector whose error grows with ``t_c``. The
standard errors of ``log c`` and ``beta`` come from the covariance matrix; with no ``sigma``
given, it is scaled by the residual variance (``absolute_sigma=False``), i.e. the scatter of
the data sets the uncertainty. ``c``'s error is propagated as ``c * se(log c)``.

``eps`` depends on the measured ``omega_c``, whose own relative uncertainty ``delta``
(:attr:`flagwrap.analysis.critical.CriticalSearch.relative_uncertainty`) shifts every
``eps`` by up to ``delta (1 + eps) `` -- large at small ``eps``. :class:`PowerLawFit` with
``machin`` given fits ``M_c`` as a third parameter, ``t_c / T = c ((M - M_c) / M_c)^-beta``,
so that the law itself locates the threshold (fixed ``beta = 1`` optional, as the paper's
line).
"""

from __future__ import annotations

import math

import numpy as np

from flagwrap.errors import UserInputError


def _log_law(log_eps, log_c, beta):
    return log_c - beta * log_eps


class PowerLawFit:
    """Fit ``t_c / T = c eps^-beta``.

    Parameters
    ----------
    fix_beta : float, optional
        hold ``beta`` at this value (fit ``c`` only; ``beta_err = 0``).

    Results (after :meth:`compute`): ``c``, ``c_err``, ``beta``, ``beta_err``, ``cov``
    (of ``(log c, beta)``), ``machin_c``/``machin_c_err`` when fitted, ``residual_rms`` (in
    ``ln t``), ``n``.
    """

    def __init__(self, fix_beta=None):
        self.fix_beta = None if fix_beta is None else float(fix_beta)
        self._computed = False

    def compute(self, eps=None, waiting_time=None, sigma_log=None, machin=None, machin_c0=None):
        """Fit.

        Parameters
        ----------
        eps : array_like, shape (K,)
            ``(omega - omega_c) / omega_c`` (> 0); ignored when ``machin`` is given.
        waiting_time : array_like, shape (K,)
            ``t_c / T`` (> 0; NaNs -- runs that did not buckle -- are dropped).
        sigma_log : array_like or float, optional
            standard error of ``ln(t_c / T)`` per point; then ``absolute_sigma=True``.
        machin : array_like, shape (K,), optional
            Machin numbers of the runs: fit ``M_c`` too (``machin_c0`` its start value, needed).

        Returns
        -------
        self
        """
        from scipy.optimize import curve_fit

        t = np.asarray(waiting_time, dtype=float)
        x = np.asarray(machin if machin is not None else eps, dtype=float)
        if t.shape != x.shape or t.ndim != 1:
            raise UserInputError("eps/machin and waiting_time must be 1-D arrays of equal length")
        ok = np.isfinite(t) & np.isfinite(x) & (t > 0)
        sig = None
        if sigma_log is not None:
            sig = np.broadcast_to(np.asarray(sigma_log, dtype=float), t.shape)[ok]
        t, x = t[ok], x[ok]
        y = np.log(t)
        self.n = int(t.size)
        self.machin_c = self.machin_c_err = float("nan")
        npar = 1 + (self.fix_beta is None) + (machin is not None)
        if self.n < npar + 1:
            raise UserInputError(f"need at least {npar + 1} buckled runs to fit {npar} parameters, got {self.n}")
        kw = {"sigma": sig, "absolute_sigma": sig is not None}
        if machin is None:
            if np.any(x <= 0):
                raise UserInputError("eps must be > 0")
            le = np.log(x)
            if self.fix_beta is None:
                p, cov = curve_fit(_log_law, le, y, p0=(math.log(0.5), 1.0), **kw)
            else:
                b = self.fix_beta
                p1, c1 = curve_fit(lambda u, lc: _log_law(u, lc, b), le, y, p0=(math.log(0.5),), **kw)
                p, cov = np.array([p1[0], b]), np.array([[c1[0, 0], 0.0], [0.0, 0.0]])
            resid = y - _log_law(le, *p)
        else:
            if machin_c0 is None:
                raise UserInputError("machin_c0 (start value of M_c) is required with machin")
            m_max = float(np.min(x))

            def law(m, lc, beta, mc):
                e = np.clip((m - mc) / mc, 1e-9, None)
                return lc - beta * np.log(e)

            if self.fix_beta is None:
                f, p0 = law, (math.log(0.5), 1.0, float(machin_c0))
                bounds = ([-np.inf, 0.0, 1e-9], [np.inf, 10.0, m_max * (1 - 1e-6)])
            else:
                b = self.fix_beta

                def f(m, lc, mc):
                    return law(m, lc, b, mc)

                p0 = (math.log(0.5), float(machin_c0))
                bounds = ([-np.inf, 1e-9], [np.inf, m_max * (1 - 1e-6)])
            p0 = (*p0[:-1], min(p0[-1], m_max * (1 - 1e-3)))  # start inside the bounds
            pp, cc = curve_fit(f, x, y, p0=p0, bounds=bounds, **kw)
            if self.fix_beta is None:
                p, cov = pp[:2], cc[:2, :2]
                self.machin_c, self.machin_c_err = float(pp[2]), float(math.sqrt(max(cc[2, 2], 0.0)))
            else:
                p = np.array([pp[0], self.fix_beta])
                cov = np.array([[cc[0, 0], 0.0], [0.0, 0.0]])
                self.machin_c, self.machin_c_err = float(pp[1]), float(math.sqrt(max(cc[1, 1], 0.0)))
            resid = y - f(x, *pp)
        self.log_c, self.beta = float(p[0]), float(p[1])
        self.cov = np.asarray(cov, dtype=float)
        self.c = math.exp(self.log_c)
        self.c_err = self.c * math.sqrt(max(self.cov[0, 0], 0.0))
        self.beta_err = math.sqrt(max(self.cov[1, 1], 0.0))
        self.residual_rms = float(np.sqrt(np.mean(resid**2)))
        self._computed = True
        return self

    def predict(self, eps):
        """``c eps^-beta``."""
        if not self._computed:
            raise AttributeError("PowerLawFit: call compute() first")
        return self.c * np.asarray(eps, dtype=float) ** (-self.beta)

    def summary(self) -> dict:
        if not self._computed:
            raise AttributeError("PowerLawFit: call compute() first")
        return {"c": self.c, "c_err": self.c_err, "beta": self.beta, "beta_err": self.beta_err,
                "machin_c": self.machin_c, "machin_c_err": self.machin_c_err,
                "residual_rms_log": self.residual_rms, "n": self.n, "fix_beta": self.fix_beta}


def departure_time(ds, rise: float = 0.05) -> float:
    """``(t_d - t_s) / T``: first time after the switch at which the 1-turn running mean of the
    free-end height is ``rise`` (default 0.05 L) above the CCW baseline, with no hold.

    A detector-light companion of ``t_c`` for rises that are oscillatory or stop half-way: it
    is :class:`~flagwrap.analysis.buckling.WaitingTime` with ``threshold=rise``,
    ``hold_turns=0``, ``onset="crossing"``. 0.05 L is above the 0.03 L re-twisting transient
    right after the switch (docs/analysis.md). nan if the height never gets there.

    Parameters
    ----------
    ds : xarray.Dataset
        a run (:func:`flagwrap.io.runfile.read_run`).
    """
    from flagwrap.analysis.buckling import WaitingTime
    from flagwrap.io.runfile import filament_slices
    from flagwrap.observables.tip import free_end_heights

    h = free_end_heights(ds["position"].values, float(ds.attrs["length"]), filament_slices(ds))
    w = WaitingTime(threshold=rise, hold_turns=0.0, onset="crossing")
    times = np.array([w.compute(ds["turns"].values, hk, ds["omega"].values).waiting_time
                      for hk in h.T])  # several flagella: the first to depart
    return float(times[np.isfinite(times)].min()) if np.isfinite(times).any() else float("nan")


def default_cw_turns(eps: float, c: float = 0.5, minimum: float = 10.0, margin: float = 5.0) -> float:
    """CW turns long enough to see an onset at ``t_c ~ 3 c / eps``: ``max(minimum, 3c/eps + margin)``."""
    return float(max(minimum, math.ceil(3.0 * c / eps + margin)))


def waiting_time_sweep(cfg, machin_c: float, eps_values, cache=None, ccw_turns: float = 5.0,
                       cw_turns=None, on_run=None) -> list:
    """Runs at ``M = (1 + eps) M_c`` for each ``eps`` and their waiting times.

    Parameters
    ----------
    cfg : flagwrap.params.Config
        geometry (motor replaced, as in :func:`flagwrap.analysis.critical.probe_config`).
    machin_c : float
        this model's measured ``M_c`` (``omega / omega_c = M / M_c``).
    eps_values : iterable of float
        ``(omega - omega_c) / omega_c`` (> -1).
    cache : flagwrap.analysis.critical.RunCache, optional
        default ``RunCache("out/waiting")``.
    ccw_turns : float
        CCW turns before the switch (5: the CCW state settles within ~4 turns).
    cw_turns : float or callable, optional
        CW turns, or ``eps -> turns``; default :func:`default_cw_turns`.
    on_run : callable, optional
        called with ``(eps, CriticalRun)`` per run.

    Returns
    -------
    list of dict
        ``eps``, ``machin``, ``omega_ratio``, ``cw_turns`` and the fields of
        :class:`~flagwrap.analysis.critical.CriticalRun`.
    """
    import dataclasses

    from flagwrap.analysis.critical import RunCache, probe_config

    cache = cache if cache is not None else RunCache("out/waiting")
    out = []
    for eps in eps_values:
        eps = float(eps)
        if not eps > -1:
            raise UserInputError(f"eps must be > -1, got {eps!r}")
        k = cw_turns(eps) if callable(cw_turns) else (default_cw_turns(eps) if cw_turns is None else float(cw_turns))
        m = (1.0 + eps) * float(machin_c)
        r = cache.run(probe_config(cfg, m, ccw_turns, k))
        if on_run is not None:
            on_run(eps, r)
        out.append({"eps": eps, "omega_ratio": 1.0 + eps, "cw_turns": k, **dataclasses.asdict(r)})
    return out
