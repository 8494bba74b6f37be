"""Free end of the filament: height and 3D trajectory (paper Fig. 4d, 4e; SI Fig. S7).

The paper follows the free end ``r(L)`` of the helix. Fig. 4(d) and SI Fig. S7(a) plot the
rescaled height ``[z(L) - z(0)] / L`` against ``t/T``; Fig. 4(e) and SI Fig. S7(b) the 3D
trajectory of ``r(L)``. A hanging helix has a negative height (it hangs toward -z below the
body); buckling shows as the free end moving upward toward the body.
"""

from __future__ import annotations

import numpy as np

from flagwrap.observables._util import positions_array, positive


def free_end_height(positions, length) -> np.ndarray:
    """Rescaled height of the free end above the clamp, ``(z(L) - z(0)) / L``.

    Parameters
    ----------
    positions : array_like, shape (T, N, 3) or (N, 3)
        bead centres [length]; bead 0 is the clamp, bead N-1 the free end.
    length : float
        filament contour length ``L`` [length], same unit as ``positions``.

    Returns
    -------
    ndarray, shape (T,) or ()
        dimensionless height (SI Fig. S7(a) ordinate).
    """
    x = positions_array(positions)
    L = positive("length", length)
    return (x[..., -1, 2] - x[..., 0, 2]) / L


def free_end_heights(positions, length, filaments=None) -> np.ndarray:
    """:func:`free_end_height` of each flagellum of a run of several, whose beads
    ``positions`` holds one after the other: ``filaments`` their bead slices (the run file's
    :func:`~flagwrap.io.runfile.filament_slices`), None for one filament.

    Returns
    -------
    ndarray, shape (T, n_filaments) or (n_filaments,)
    """
    x = positions_array(positions)
    sl = [slice(0, x.shape[-2])] if filaments is None else list(filaments)
    if not sl or any(s.stop > x.shape[-2] or s.stop - s.start < 2 for s in sl):
        raise ValueError(f"filament slices {sl} do not fit {x.shape[-2]} beads")
    first = np.array([s.start for s in sl])
    last = np.array([s.stop - 1 for s in sl])
    return (x[..., last, 2] - x[..., first, 2]) / positive("length", length)


def tip_trajectory(positions, length=None, relative_to_clamp: bool = True) -> np.ndarray:
    """Trajectory of the free end ``r(L)`` (paper Fig. 4(e)).

    Parameters
    ----------
    positions : array_like, shape (T, N, 3) or (N, 3)
        bead centres [length].
    length : float, optional
        if given, the result is divided by ``L`` (dimensionless); else it keeps the unit of
        ``positions``.
    relative_to_clamp : bool
        subtract the clamp position ``r(0)`` (the paper's ``r(L) - r(0)``).

    Returns
    -------
    ndarray, shape (T, 3) or (3,)
    """
    x = positions_array(positions)
    tip = x[..., -1, :] - (x[..., 0, :] if relative_to_clamp else 0.0)
    if length is not None:
        tip = tip / positive("length", length)
    return tip
