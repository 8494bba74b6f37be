"""Density of the iron-oxide-filled elastomer (SI, "Fabrication of the helical rod").

Mixing rule (SI, unnumbered equation)::

    rho_eff = (m_base + m_cat + m_FeO) / ((m_base + m_cat)/rho_HTV + m_FeO/rho_FeO)

and its inverse, the powder mass that gives a target density::

    m_FeO = (m_base + m_cat) rho_FeO (rho_t - rho_HTV) / (rho_HTV (rho_FeO - rho_t)),
    valid for rho_HTV <= rho_t < rho_FeO.

Masses in any one unit (only their ratios enter); densities in any one unit (SI uses g/cm^3;
the defaults here are kg/m^3).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from flagwrap.errors import UserInputError

__all__ = [
    "RHO_HTV",
    "RHO_FEO",
    "RHO_GLYCERIN",
    "effective_density",
    "powder_mass_for_density",
    "density_mismatch",
]

#: density of the HTV-4000 elastomer [kg/m^3] (SI)
RHO_HTV = 1150.0
#: density of the iron oxide powder [kg/m^3] (SI; printed without unit, read as g/cm^3)
RHO_FEO = 5740.0
#: density of the glycerin [kg/m^3] (SI)
RHO_GLYCERIN = 1250.0


def _pos(name: str, value: float) -> float:
    from flagwrap.errors import check_positive

    return check_positive(name, value)


def effective_density(
    mass_base: ArrayLike,
    mass_catalyst: ArrayLike,
    mass_powder: ArrayLike,
    rho_polymer: float = RHO_HTV,
    rho_powder: float = RHO_FEO,
) -> np.ndarray:
    """Density of the cured mixture (SI, ideal volume additivity).

    Parameters
    ----------
    mass_base, mass_catalyst, mass_powder : array_like
        component masses [mass], >= 0, base + catalyst > 0.
    rho_polymer, rho_powder : float
        ``rho_HTV`` and ``rho_FeO`` [density].

    Returns
    -------
    ndarray
        ``rho_eff`` [density, same unit as the inputs].

    Examples
    --------
    >>> float(effective_density(50.0, 50.0, 0.0))
    1150.0
    """
    mb = np.asarray(mass_base, dtype=float)
    mc = np.asarray(mass_catalyst, dtype=float)
    mf = np.asarray(mass_powder, dtype=float)
    if np.any(mb < 0) or np.any(mc < 0) or np.any(mf < 0):
        raise UserInputError("masses must be >= 0")
    mp = mb + mc
    if np.any(mp <= 0):
        raise UserInputError("base + catalyst mass must be > 0")
    rp, rf = _pos("rho_polymer", rho_polymer), _pos("rho_powder", rho_powder)
    return (mp + mf) / (mp / rp + mf / rf)


def powder_mass_for_density(
    mass_polymer: ArrayLike,
    target_density: float = RHO_GLYCERIN,
    rho_polymer: float = RHO_HTV,
    rho_powder: float = RHO_FEO,
) -> np.ndarray:
    """Powder mass that brings ``mass_polymer`` (base + catalyst) to ``target_density``.

    Inverse of :func:`effective_density`. For the SI's materials and glycerin
    (1.15, 5.74, 1.25 g/cm^3) it is 0.1112 g of iron oxide per g of polymer.

    Parameters
    ----------
    mass_polymer : array_like
        base + catalyst mass [mass], > 0.
    target_density : float
        [density], with ``rho_polymer <= target < rho_powder``.
    """
    mp = np.asarray(mass_polymer, dtype=float)
    if np.any(mp <= 0):
        raise UserInputError("mass_polymer must be > 0")
    rt = _pos("target_density", target_density)
    rp, rf = _pos("rho_polymer", rho_polymer), _pos("rho_powder", rho_powder)
    if not (rp <= rt < rf):
        raise UserInputError(
            f"target_density must lie in [rho_polymer, rho_powder) = [{rp}, {rf}), got {rt}"
        )
    return mp * rf * (rt - rp) / (rp * (rf - rt))


def density_mismatch(rho_eff: ArrayLike, rho_fluid: float = RHO_GLYCERIN) -> np.ndarray:
    """``|rho_eff - rho_gly| / rho_gly`` (SI: typically 1-2 %, always < 5 %). Dimensionless."""
    return np.abs(np.asarray(rho_eff, dtype=float) - _pos("rho_fluid", rho_fluid)) / float(rho_fluid)
