"""Distance of the beads from the cell body and "beside the body" masks.

The body is the simulator's (:mod:`flagwrap.body.shapes`; the paper's capped cylinder by
default: a hemisphere of radius ``R_cell`` centred at ``(0, 0, R_cell)``, its lowest point the
clamp at the origin, and a cylinder of the same radius up to ``z = R_cell + H``). Distances
are from bead centres to the surface, negative inside, in the unit of the positions.
"""

from __future__ import annotations

import numpy as np

from flagwrap.errors import UserInputError
from flagwrap.observables._util import positions_array, positive


def body_distance(positions, body_radius, body_length, shape="capped-cylinder") -> np.ndarray:
    """Signed distance of every bead centre from the body surface.

    Parameters
    ----------
    positions : array_like, shape (..., N, 3)
        bead centres [length].
    body_radius, body_length : float
        ``R_cell`` and the cylinder length ``H`` [length].
    shape : str or BodyShape
        the body's shape: a name (``body.shape``: :func:`flagwrap.body.shapes.make_shape`
        builds it at ``body_radius``, ``body_length``) or a shape object of this unit.

    Returns
    -------
    ndarray, shape (..., N)
        [length], negative inside the body. Same law as the simulator's contact kernel.
    """
    from flagwrap.body.shapes import make_shape

    x = positions_array(positions, min_beads=1)
    if isinstance(shape, str):
        Rc = positive("body_radius", body_radius)
        H = float(body_length)
        if not H >= 0:
            raise UserInputError(f"body_length must be >= 0, got {body_length!r}")
        shape = make_shape(shape, Rc, H)
    return shape.distance(x)


def near_body_mask(positions, body_radius, body_length, max_distance, z_min=0.0,
                   first_bead: int = 2, shape="capped-cylinder") -> np.ndarray:
    """Beads beside the body: ``distance <= max_distance`` and ``z > z_min``, from ``first_bead``.

    Parameters
    ----------
    positions : array_like, shape (..., N, 3)
        bead centres [length].
    body_radius, body_length : float
        ``R_cell``, ``H`` [length].
    max_distance : float
        [length] largest bead-surface distance that counts as beside the body.
    z_min : float
        [length] beads must be above this height; the default 0 (the bottom of the cap, the
        clamp height) keeps beads that have come up alongside the body, not the hanging part.
    first_bead : int
        beads before it (the clamp and its neighbour, which sit at the cap by construction)
        never count.

    Returns
    -------
    ndarray of bool, shape (..., N)
    """
    x = positions_array(positions, min_beads=1)
    d = body_distance(x, body_radius, body_length, shape)
    m = (d <= float(max_distance)) & (x[..., 2] > float(z_min))
    m[..., : int(first_bead)] = False
    return m


def near_body_fraction(mask, first_bead: int = 2) -> np.ndarray:
    """Fraction of beads ``first_bead..N-1`` selected by ``mask``, shape ``(...)``."""
    m = np.asarray(mask, dtype=bool)[..., int(first_bead):]
    if m.shape[-1] == 0:
        raise UserInputError("no beads beyond first_bead")
    return m.mean(axis=-1)
