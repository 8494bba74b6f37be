"""Fixed no-slip boundaries other than the plane wall: tubes and constrictions
(:mod:`.tube`; docs/confinement.md). The plane wall is a mobility of its own
(:mod:`flagwrap.hydrodynamics.wall`); a tube is a surface of blobs held still."""

from flagwrap.confinement.tube import Tube

__all__ = ["Tube"]
