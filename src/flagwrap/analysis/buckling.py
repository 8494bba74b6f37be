"""Buckling onset, waiting time ``t_c`` and final state of a CCW -> CW run.

Paper (main text, "Slow dynamics right above the onset of buckling"; SI "Post-buckling
dynamics", Fig. S7(a)): after the motor switches from CCW to CW, the free end of a
supercritical helix waits a time ``t_c`` and then "starts moving upward"; ``t_c / T ~ 1/eps``
(Eq. 3, Fig. 6). The paper marks ``t_c`` by eye. Here it is a documented, noise-robust rule
on the rescaled free-end height ``h(t) = (z(L) - z(0)) / L``:

1. **Switch.** ``t_s`` = last saved time with ``omega >= 0`` before the first ``omega < 0``
   that follows a CCW phase (``t/T`` of the switch to within one save interval).
2. **Smoothing.** ``h_s`` = centred running mean of ``h`` over ``smooth_turns`` motor turns.
   One turn removes the once-per-turn whirling oscillation of the tip (amplitude up to
   ~0.02 L in the stored runs) without shifting a linear ramp in time.
3. **Baseline.** ``h_0`` = median of ``h`` over the last ``baseline_turns`` of the CCW phase,
   the steadily whirling state after the paper's 10 equilibration turns. (An early-CW window
   would not exist when ``t_c < 1 T``, the regime ``omega/omega_c > 2`` of Fig. 6.) Without a
   CCW phase the first frame's height is used.
4. **Buckled?** ``t_x`` = first time after ``t_s`` with ``h_s - h_0 >= threshold`` and staying
   there for ``hold_turns`` (or to the end of the run, if at least half of ``hold_turns`` is
   left). No such time: not buckled (``t_c = nan``).
5. **Onset.** ``t_c`` is where the rise that leads to ``t_x`` starts: a broken-stick fit
   ``h = c + s max(t - t_k, 0)`` (``s > 0``) by least squares to the unsmoothed height on
   ``[t_s, t_x']``, minimised over the hinge ``t_k`` on the sample grid;
   ``t_c = t_k - t_s`` [turns]. The fit uses the whole rise, so it is insensitive to noise
   on any single sample (the whirling oscillation averages out over the window); unlike a
   threshold crossing it does not depend much on ``threshold``, and unlike a fit to the
   smoothed curve it is not pulled earlier by half a smoothing window when the rise is
   abrupt (a step at ``t*`` gives ``t_k`` within a sample or two of ``t*``). For the stored
   ``M = 600`` run it gives ``t_c = 2.1 T`` (the height leaves its CW plateau, -0.326 L, at
   1.8-2.0 T by eye; a broken stick lands slightly late on a convex, exponential-like rise).
   ``t_x'`` is the first time from ``t_x`` on at which the unsmoothed height has crossed the
   threshold too (at most ``smooth_turns / 2`` after ``t_x``). ``onset="crossing"`` gives
   ``t_x - t_s`` instead.

Defaults, from the stored runs (L = 0.4 m, R/L = 0.075, helix hanging at ``h ~ -0.35``): the
stable ``M = 283`` run stays within 0.011 L of its CCW baseline in the CW phase, the
buckling ``M = 600`` run shows a 0.03 L re-twisting transient right after the switch and then
rises by 0.35 L to ``h ~ 0``; the no-HI ``M = 283`` run settles 0.13 L higher without the
free end ever coming up. ``threshold = 0.15`` (in units of L) separates all three: above
steady re-twisting and deformed-whirling offsets, well below the ~0.35 L of a free end that
comes up to the body. ``hold_turns = 1`` rejects a transient excursion of less than a turn.

Final state (main text Fig. 5: open circles "stable", filled squares "wrapping", filled
circles "folding (i.e. incomplete wrapping)"), judged over the last ``final_turns`` of the
run by the median over frames of two observables of the beads beside the body -- beads
``first_bead..N-1`` above the cap bottom (``z > 0``) within ``contact_distance * R_cell`` of
the surface:

* ``contact_fraction`` -- the fraction of beads beside the body;
* ``winding`` -- ``|W| / 2 pi`` over bonds between such beads (:mod:`flagwrap.observables.winding`).

``stable``: not buckled. ``wrapping``: buckled, ``winding >= min_winding_turns`` and
``contact_fraction >= min_contact_fraction``. ``folding``: buckled otherwise. Defaults:
``contact_distance = 0.5`` (half a body radius: the paper's coils have ``R = 0.6 R_cell``, so a
coil that encloses the body lies within ``~R`` of it), ``min_winding_turns = 0.5`` and
``min_contact_fraction = 0.3``: a filament of length L can wind at most
``L / (2 pi R_cell)`` turns (1.3 for the stored runs), so requiring a full turn would call a
tightly wrapped short filament "folding"; half a turn with a third of the filament beside
the body is a coil around the body, which a fold (a hairpin that comes up beside the body
without encircling it) does not reach.
"""

from __future__ import annotations

import numpy as np

from flagwrap.errors import UserInputError, check_positive
from flagwrap.observables import (
    cw_torque_peak,
    free_end_height,
    local_handedness,
    near_body_fraction,
    near_body_mask,
    perversion_index,
    plateau_value,
    winding_turns,
)

STATES = ("stable", "folding", "wrapping")


def _positive(name, value, allow_zero=False):
    return check_positive(name, value, allow_zero=allow_zero)


def _series(turns, *arrays):
    t = np.asarray(turns, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise UserInputError(f"turns must be 1-D with at least 2 samples, got shape {t.shape}")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise UserInputError("turns must be finite and strictly increasing")
    out = [t]
    for a in arrays:
        a = np.asarray(a, dtype=float)
        if a.shape[:1] != t.shape:
            raise UserInputError(f"series of shape {a.shape} does not match {t.size} times")
        out.append(a)
    return out


def find_switch(turns, omega) -> int:
    """Index of the first CW sample after the CCW -> CW switch.

    Parameters
    ----------
    turns : array_like, shape (T,)
        ``t / T``.
    omega : array_like, shape (T,)
        signed motor angular velocity (CCW > 0, CW < 0), any unit.

    Returns
    -------
    int
        ``i`` with ``omega[i] < 0`` and ``omega[i-1] >= 0`` after some ``omega > 0``; 0 if the run
        is CW from its start. The switch time is ``turns[i-1]`` (``turns[0]`` if ``i == 0``).

    Raises
    ------
    UserInputError
        if the motor never turns CW.
    """
    t, om = _series(turns, omega)
    cw = om < 0
    if not cw.any():
        raise UserInputError("the motor never turns CW (no CCW -> CW switch to analyse)")
    ccw_seen = np.cumsum(om > 0) > 0
    cand = np.flatnonzero(cw[1:] & ~cw[:-1] & ccw_seen[:-1]) + 1
    if cand.size:
        return int(cand[0])
    if cw[0] or (om[0] == 0 and cw[np.argmax(om != 0)]):
        return int(np.argmax(cw)) if not cw[0] else 0
    raise UserInputError("could not locate the CCW -> CW switch")


def _running_mean(y, width):
    from scipy.ndimage import uniform_filter1d

    return uniform_filter1d(y, size=max(1, int(width)), mode="nearest") if width > 1 else y.copy()


def _hinge_fit(t, y):
    """Hinge index of the best broken-stick fit ``y = c + s max(t - t_k, 0)``, ``s > 0``."""
    best, best_k = np.inf, 0
    n = t.size
    for k in range(0, n - 1):
        r = np.maximum(t - t[k], 0.0)
        A = np.stack([np.ones(n), r], axis=1)
        coef, *_ = np.linalg.lstsq(A, y, rcond=None)
        if coef[1] <= 0:
            continue
        sse = float(np.sum((A @ coef - y) ** 2))
        if sse < best - 1e-15:
            best, best_k = sse, k
    return best_k


class _Compute:
    """Guarded results: properties raise until :meth:`compute` has run."""

    _computed = False

    def _need(self):
        if not self._computed:
            raise AttributeError(f"{type(self).__name__}: call compute() first")


class WaitingTime(_Compute):
    """Buckling onset after the CCW -> CW switch and the waiting time ``t_c / T``.

    See the module docstring for the criterion and the choice of defaults.

    Parameters
    ----------
    threshold : float
        rise of the smoothed free-end height above the CCW baseline that counts as buckling
        [units of L]; default 0.15.
    hold_turns : float
        the rise must persist this long [turns]; default 1.
    smooth_turns : float
        running-mean window [turns]; default 1.
    baseline_turns : float
        CCW window for the baseline median [turns]; default 1.
    onset : {"hinge", "crossing"}
        ``t_c`` from the broken-stick fit (default) or the threshold crossing time.
    """

    def __init__(self, threshold=0.15, hold_turns=1.0, smooth_turns=1.0, baseline_turns=1.0,
                 onset="hinge"):
        self.threshold = _positive("threshold", threshold)
        self.hold_turns = _positive("hold_turns", hold_turns, allow_zero=True)
        self.smooth_turns = _positive("smooth_turns", smooth_turns, allow_zero=True)
        self.baseline_turns = _positive("baseline_turns", baseline_turns)
        if onset not in ("hinge", "crossing"):
            raise UserInputError(f"onset must be 'hinge' or 'crossing', got {onset!r}")
        self.onset = onset

    def params(self) -> dict:
        return {"threshold": self.threshold, "hold_turns": self.hold_turns,
                "smooth_turns": self.smooth_turns, "baseline_turns": self.baseline_turns,
                "onset": self.onset}

    def compute(self, turns, height, omega):
        """Detect the onset.

        Parameters
        ----------
        turns : array_like, shape (T,)
            ``t / T``, strictly increasing, uniformly sampled (the run file's save grid).
        height : array_like, shape (T,)
            ``(z(L) - z(0)) / L`` (:func:`flagwrap.observables.free_end_height`).
        omega : array_like, shape (T,)
            signed motor speed (CCW > 0).

        Returns
        -------
        self
        """
        t, h, om = _series(turns, height, omega)
        if not np.all(np.isfinite(h)):
            raise UserInputError("free-end height contains NaN/inf")
        dt = float(np.median(np.diff(t)))
        i_s = find_switch(t, om)
        t_s = t[i_s - 1] if i_s > 0 else t[0]
        hs = _running_mean(h, round(self.smooth_turns / dt))
        # baseline: the last baseline_turns of CCW driving before the switch (a "stop" phase
        # may lie between; a window ending at t_s would then miss the relaxed CCW state)
        ccw = np.flatnonzero((om > 0) & (t <= t_s))
        pre = np.zeros_like(t, dtype=bool)
        if ccw.size:
            t_ccw = t[ccw[-1]]
            pre = (om > 0) & (t <= t_ccw) & (t > t_ccw - self.baseline_turns)
        base = float(np.median(h[pre])) if pre.any() else float(h[0])
        above = hs - base >= self.threshold
        m = max(1, int(round(self.hold_turns / dt)))
        i_x = None
        for i in np.flatnonzero(above[i_s:]) + i_s:
            seg = above[i:i + m]
            if seg.all() and (seg.size == m or seg.size >= max(1, m // 2)):
                i_x = int(i)
                break
        self._switch_index, self._switch_turns, self._baseline = i_s, float(t_s), base
        self._smoothed, self._turns = hs, t
        self._crossing_index = i_x
        if i_x is None:
            self._onset_turns = float("nan")
        elif self.onset == "crossing":
            self._onset_turns = float(t[i_x])
        else:
            j0 = max(i_s - 1, 0)
            # end of the fit window: where the raw height has crossed too (an abrupt rise
            # makes the smoothed curve cross up to half a window early), at most half a
            # smoothing window after t_x
            half = max(1, int(round(0.5 * self.smooth_turns / dt)))
            late = np.flatnonzero(h[i_x:i_x + half + 1] - base >= self.threshold)
            j1 = i_x + (int(late[0]) if late.size else half)
            j1 = min(j1, t.size - 1)
            k = _hinge_fit(t[j0:j1 + 1], h[j0:j1 + 1])
            self._onset_turns = float(t[j0 + k])
        self._computed = True
        return self

    @property
    def switch_turns(self) -> float:
        """``t_s / T`` of the CCW -> CW switch."""
        self._need()
        return self._switch_turns

    @property
    def switch_index(self) -> int:
        self._need()
        return self._switch_index

    @property
    def baseline(self) -> float:
        """CCW baseline ``h_0`` of the free-end height [units of L]."""
        self._need()
        return self._baseline

    @property
    def smoothed(self) -> np.ndarray:
        """Smoothed free-end height ``h_s`` (T,) [units of L]."""
        self._need()
        return self._smoothed

    @property
    def buckled(self) -> bool:
        self._need()
        return self._crossing_index is not None

    @property
    def crossing_turns(self) -> float:
        """``t_x / T`` of the persistent threshold crossing (nan if not buckled)."""
        self._need()
        return float("nan") if self._crossing_index is None else float(self._turns[self._crossing_index])

    @property
    def onset_turns(self) -> float:
        """``t / T`` at which the free end starts moving upward (nan if not buckled)."""
        self._need()
        return self._onset_turns

    @property
    def waiting_time(self) -> float:
        """``t_c / T`` measured from the switch (paper Fig. 6); nan if not buckled."""
        self._need()
        return self._onset_turns - self._switch_turns

    def plot(self, ax=None, height=None):
        """Smoothed height, baseline, threshold and onset against ``t/T`` (SI Fig. S7(a))."""
        self._need()
        if ax is None:
            import matplotlib.pyplot as plt

            _, ax = plt.subplots()
        t = self._turns - self._switch_turns
        if height is not None:
            ax.plot(t, height, color="0.7", lw=0.8, label="h")
        ax.plot(t, self._smoothed, label="h smoothed")
        ax.axhline(self._baseline, ls=":", color="k", label="baseline")
        ax.axhline(self._baseline + self.threshold, ls="--", color="k", label="threshold")
        if self.buckled:
            i = int(np.argmin(np.abs(self._turns - self._onset_turns)))
            ax.plot(t[i], self._smoothed[i], "o", color="r", label="$t_c$")
        ax.set_xlabel("t/T after switch")
        ax.set_ylabel("[z(L) - z(0)] / L")
        ax.legend()
        return ax


class FinalState(_Compute):
    """Final state of a run: "stable", "folding" or "wrapping" (paper Fig. 5 symbols).

    See the module docstring for the criterion and the choice of defaults.

    Parameters
    ----------
    min_winding_turns : float
        winding about the body axis of the beads beside the body that counts as wrapped
        [turns]; default 0.5.
    min_contact_fraction : float
        fraction of the beads that must be beside the body; default 0.3.
    contact_distance : float
        beside the body = within ``contact_distance * R_cell`` of its surface and above
        ``z = 0``; default 0.5.
    final_turns : float
        window at the end of the run over which the medians are taken [turns]; default 1.
    first_bead : int
        beads before it (clamp) never count; default 2.
    """

    def __init__(self, min_winding_turns=0.5, min_contact_fraction=0.3, contact_distance=0.5,
                 final_turns=1.0, first_bead=2):
        self.min_winding_turns = _positive("min_winding_turns", min_winding_turns)
        self.min_contact_fraction = _positive("min_contact_fraction", min_contact_fraction)
        if self.min_contact_fraction > 1:
            raise UserInputError(f"min_contact_fraction must be <= 1, got {min_contact_fraction!r}")
        self.contact_distance = _positive("contact_distance", contact_distance)
        self.final_turns = _positive("final_turns", final_turns)
        self.first_bead = int(first_bead)
        if self.first_bead < 0:
            raise UserInputError(f"first_bead must be >= 0, got {first_bead!r}")

    def params(self) -> dict:
        return {"min_winding_turns": self.min_winding_turns,
                "min_contact_fraction": self.min_contact_fraction,
                "contact_distance": self.contact_distance, "final_turns": self.final_turns,
                "first_bead": self.first_bead}

    def compute(self, turns, positions, buckled, body_radius, body_length,
                body_shape="capped-cylinder"):
        """Classify.

        Parameters
        ----------
        turns : array_like, shape (T,)
            ``t / T``.
        positions : array_like, shape (T, N, 3)
            bead centres [length], same unit as the body dimensions.
        buckled : bool
            from :class:`WaitingTime`.
        body_radius, body_length : float
            ``R_cell``, cylinder length ``H`` [length].
        body_shape : the body's shape (:class:`flagwrap.params.CellBody`)

        Returns
        -------
        self
        """
        t, x = _series(turns, positions)
        if x.ndim != 3 or x.shape[2] != 3 or x.shape[1] <= self.first_bead + 1:
            raise UserInputError(f"positions must have shape (T, N, 3) with N > first_bead + 1, got {x.shape}")
        mask = near_body_mask(x, body_radius, body_length,
                              self.contact_distance * float(body_radius), z_min=0.0,
                              first_bead=self.first_bead, shape=body_shape)
        self._contact = near_body_fraction(mask, self.first_bead)
        self._winding = np.abs(winding_turns(x, mask))
        self._turns = t
        self._final_contact = plateau_value(t, self._contact, self.final_turns)
        self._final_winding = plateau_value(t, self._winding, self.final_turns)
        self._buckled = bool(buckled)
        if not self._buckled:
            self._state = "stable"
        elif (self._final_winding >= self.min_winding_turns
              and self._final_contact >= self.min_contact_fraction):
            self._state = "wrapping"
        else:
            self._state = "folding"
        self._computed = True
        return self

    @property
    def state(self) -> str:
        """One of :data:`STATES`."""
        self._need()
        return self._state

    @property
    def winding(self) -> float:
        """Final median ``|W| / 2 pi`` of the beads beside the body [turns]."""
        self._need()
        return self._final_winding

    @property
    def contact_fraction(self) -> float:
        """Final median fraction of beads beside the body."""
        self._need()
        return self._final_contact

    @property
    def winding_series(self) -> np.ndarray:
        """``|W| / 2 pi`` per frame (T,) [turns]."""
        self._need()
        return self._winding

    @property
    def contact_series(self) -> np.ndarray:
        """Fraction of beads beside the body per frame (T,)."""
        self._need()
        return self._contact

    def plot(self, ax=None):
        """Winding and contact fraction against ``t/T`` with the thresholds."""
        self._need()
        if ax is None:
            import matplotlib.pyplot as plt

            _, ax = plt.subplots()
        ax.plot(self._turns, self._winding, label="winding [turns]")
        ax.plot(self._turns, self._contact, label="beside-body fraction")
        ax.axhline(self.min_winding_turns, ls="--", color="C0")
        ax.axhline(self.min_contact_fraction, ls="--", color="C1")
        ax.set_xlabel("t/T")
        ax.set_title(self._state)
        ax.legend()
        return ax


class BucklingAnalysis(_Compute):
    """Waiting time, final state, perversion onset and torque summary of one run.

    Parameters
    ----------
    waiting_time : WaitingTime, optional
    final_state : FinalState, optional
        configured detectors (defaults if omitted).
    min_section : int
        :func:`flagwrap.observables.perversions` denoising length; default 3.
    """

    def __init__(self, waiting_time=None, final_state=None, min_section=3):
        self.waiting = waiting_time if waiting_time is not None else WaitingTime()
        self.final = final_state if final_state is not None else FinalState()
        self.min_section = int(min_section)

    def params(self) -> dict:
        return {**self.waiting.params(), **self.final.params(), "min_section": self.min_section}

    def compute(self, turns, positions, omega, length, body_radius, body_length, torque_reduced=None,
                body_shape="capped-cylinder"):
        """Run all detectors.

        Parameters
        ----------
        turns, omega : array_like, shape (T,)
            ``t / T`` and the signed motor speed.
        positions : array_like, shape (T, N, 3)
            bead centres [length].
        length, body_radius, body_length : float
            ``L``, ``R_cell``, ``H`` [length].
        torque_reduced : array_like, shape (T,), optional
            ``N_m R / A``; gives the CW torque peak and final plateau.

        Returns
        -------
        self
        """
        t, x, om = _series(turns, positions, omega)
        self.height = free_end_height(x, length)
        self.waiting.compute(t, self.height, om)
        self.final.compute(t, x, self.waiting.buckled, body_radius, body_length, body_shape)
        hand = local_handedness(x)
        self.perversion_bead = perversion_index(hand, self.min_section)
        after = t > self.waiting.switch_turns
        has = (self.perversion_bead >= 0) & after
        i = np.flatnonzero(has)
        self.perversion_turns = float(t[i[0]] - self.waiting.switch_turns) if i.size else float("nan")
        if torque_reduced is not None:
            _, tq = _series(t, torque_reduced)
            self.torque_peak, self.torque_peak_turns = cw_torque_peak(t, tq, self.waiting.switch_turns)
            self.torque_final = plateau_value(t, tq, self.final.final_turns)
        else:
            self.torque_peak = self.torque_peak_turns = self.torque_final = float("nan")
        self._computed = True
        return self

    def summary(self) -> dict:
        """Scalar results (JSON-serialisable; nan where undefined)."""
        self._need()
        w, f = self.waiting, self.final
        final_height = plateau_value(w._turns, self.height, f.final_turns)
        return {
            "state": f.state,
            "buckled": w.buckled,
            # the rise still there over the final window: a decaying wobble on a soft hook
            # (docs/bacterium.md, C. insecticola) crosses the threshold for a turn and comes
            # back; the paper's rule calls it buckled, this says it did not last
            "sustained": bool(w.buckled and final_height - w.baseline >= w.threshold),
            "switch_turns": w.switch_turns,
            "baseline_height": w.baseline,
            "waiting_time_turns": w.waiting_time,
            "crossing_turns": w.crossing_turns - w.switch_turns,
            "perversion_turns": self.perversion_turns,
            "final_height": final_height,
            "max_height": float(np.max(self.height[w.switch_index:])),
            "winding_turns": f.winding,
            "contact_fraction": f.contact_fraction,
            "torque_peak_reduced": self.torque_peak,
            "torque_peak_turns": self.torque_peak_turns,
            "torque_final_reduced": self.torque_final,
        }
