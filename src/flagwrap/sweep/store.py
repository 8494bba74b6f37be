"""Hashed case store of a sweep: one run file and one row file per case, written atomically.

Layout of ``out/sweeps/<name>/``::

    runs/<key>.nc          the run file (flagwrap.io.runfile, atomic rename)
    rows/<key>.json        the case's row: parameters, status, class, t_c, error (atomic rename)
    boundary/<gkey>.json   boundary mode: M_c bracket of one geometry (atomic rename)
    critical/              boundary mode: the analysis.critical run cache of the searches
    current.json           the row keys and geometry keys of the spec last run here
                           (written when a sweep starts and again when it ends; boundary
                           rows count once their geometry's search has finished): the
                           table, the boundaries and the diagram show those only
    table.parquet          the table of all rows, rewritten at the end of each sweep
                           (without pyarrow: table.nc, netCDF4, and table.csv)

A row is written with ``tempfile`` + ``fsync`` + ``os.replace`` into ``rows/``: after a
SIGKILL at any instant a row exists complete or not at all, and one file per key makes a
duplicated row impossible. Nothing is appended in place. The table is built by reading the
rows (:meth:`SweepStore.table`); the exported file is only a convenience copy. Rows of an
earlier version of the spec (another tolerance, say) stay on disk, reused if the spec comes
back, but are not mixed into the table: ``current.json`` names the current ones.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from flagwrap.io.atomic import atomic_write, remove_stale_temporaries

#: columns that differ between two runs of the same case (timing, host); excluded from
#: :meth:`SweepStore.table` with ``volatile=False``
VOLATILE = ("wall_time_s", "finished_at", "host", "run_file")


def write_json_atomic(obj, path) -> Path:
    """Write ``obj`` as JSON to ``path`` atomically (see :mod:`flagwrap.io.atomic`)."""
    text = json.dumps(obj, sort_keys=True, indent=1, allow_nan=False)
    return atomic_write(path, lambda tmp: tmp.write_text(text))


#: the field of a row or boundary file holding the SHA-256 of the rest of it
CHECKSUM = "_sha256"


def _digest(obj: dict) -> str:
    import hashlib

    body = json.dumps({k: v for k, v in obj.items() if k != CHECKSUM}, sort_keys=True,
                      allow_nan=False)
    return hashlib.sha256(body.encode()).hexdigest()


def write_checked_json(obj: dict, path) -> Path:
    """:func:`write_json_atomic` of ``obj`` with its checksum (:func:`read_checked_json`)."""
    obj = {k: v for k, v in obj.items() if k != CHECKSUM}
    return write_json_atomic({**obj, CHECKSUM: _digest(obj)}, path)


def read_checked_json(path, need=()) -> tuple[dict | None, str]:
    """``(object, "")`` of a sound row or boundary file, ``(None, why)`` of a damaged one:
    not readable JSON, not an object, a checksum that does not match (files written before
    checksums have none: their fields alone are checked), or a key of ``need`` missing."""
    try:
        obj = json.loads(Path(path).read_text())
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        return None, f"not readable JSON: {exc}"
    if not isinstance(obj, dict):
        return None, "not a JSON object"
    if CHECKSUM in obj and obj[CHECKSUM] != _digest(obj):
        return None, "its checksum does not match"
    missing = [k for k in need if k not in obj]
    if missing:
        return None, f"no {', '.join(missing)}"
    obj.pop(CHECKSUM, None)
    return obj, ""


def _damaged(path, why: str) -> None:
    import sys

    print(f"flagwrap: {path} is damaged ({why}); it is left out (a rerun of the sweep "
          "computes it again)", file=sys.stderr)


def _row_sound(row: dict, key: str) -> str:
    """Why ``row`` (read from ``rows/<key>.json``) cannot be trusted, or ""."""
    if row.get("key") != key:
        return f"key {row.get('key')!r} is not its file's {key!r}"
    if row.get("status") not in ("ok", "failed"):
        return f"status = {row.get('status')!r} is not 'ok' or 'failed'"
    if row.get("buckled") is not None and not isinstance(row["buckled"], bool):
        return f"buckled = {row['buckled']!r} is not a bool"
    return ""


def jsonable(obj):
    """NaN/inf -> None, numpy scalars and arrays -> Python, recursively."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if hasattr(obj, "tolist") and getattr(obj, "ndim", 0) > 0:  # a numpy array
        obj = obj.tolist()
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if hasattr(obj, "item") and not isinstance(obj, (str, bytes)):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, (bool, int, float, str)) or obj is None:
        return obj
    return str(obj)


class SweepStore:
    """The folder of one sweep (see the module docstring).

    Parameters
    ----------
    root : path-like
        ``out/sweeps/<name>``; created on first write.
    """

    def __init__(self, root):
        self.root = Path(root)
        self.runs = self.root / "runs"
        self.rows = self.root / "rows"
        self.boundary = self.root / "boundary"
        self.critical = self.root / "critical"

    def run_path(self, key: str) -> Path:
        return self.runs / f"{key}.nc"

    def row_path(self, key: str) -> Path:
        return self.rows / f"{key}.json"

    def has_row(self, key: str) -> bool:
        """A sound row (:meth:`read_row`): a damaged one counts as missing, so a rerun
        computes the case again."""
        return self.read_row(key) is not None

    def read_row(self, key: str) -> dict | None:
        """The row of ``key``, ``None`` if there is none or it is damaged (named on stderr:
        unreadable, checksum, key, status or verdict of the wrong kind)."""
        p = self.row_path(key)
        if not p.is_file():
            return None
        row, why = read_checked_json(p, need=("key", "status"))
        why = why or _row_sound(row, key)
        if why:
            _damaged(p, why)
            return None
        return row

    def write_row(self, row: dict) -> Path:
        """Write ``row`` (must hold ``key``) atomically to ``rows/<key>.json``, with its
        checksum."""
        return write_checked_json(jsonable(row), self.row_path(row["key"]))

    def read_boundary(self, gkey: str) -> dict | None:
        p = self.boundary / f"{gkey}.json"
        if not p.is_file():
            return None
        res, why = read_checked_json(p)
        if why:
            _damaged(p, why)
        return res

    def write_boundary(self, gkey: str, result: dict) -> Path:
        return write_checked_json(jsonable(result), self.boundary / f"{gkey}.json")

    def clean(self) -> int:
        """Remove temporary files left by killed writers (not a live worker's: another sweep
        process or a cluster worker may be writing here); returns how many."""
        return sum(len(remove_stale_temporaries(folder=d))
                   for d in (self.runs, self.rows, self.boundary, self.critical) if d.is_dir())

    @property
    def manifest_path(self) -> Path:
        return self.root / "current.json"

    def write_manifest(self, row_keys, gkeys=()) -> Path:
        """Record the keys of the spec just run (see the module docstring)."""
        return write_checked_json({"rows": sorted(set(row_keys)),
                                   "boundaries": sorted(set(gkeys))}, self.manifest_path)

    def _current(self, kind: str) -> set | None:
        p = self.manifest_path
        if not p.is_file():
            return None
        man, why = read_checked_json(p, need=(kind,))
        if why or not isinstance(man[kind], list):
            _damaged(p, why or f"{kind} is not a list")
            return None  # every row on disk, rather than none
        return set(man[kind])

    def iter_rows(self, everything: bool = False):
        """The current spec's complete rows, sorted by key (all rows on disk if
        ``everything`` or if no sweep has started here yet)."""
        if not self.rows.is_dir():
            return
        keep = None if everything else self._current("rows")
        for p in sorted(self.rows.glob("*.json")):
            if keep is None or p.stem in keep:
                row = self.read_row(p.stem)  # a damaged row is named and left out
                if row is not None:
                    yield row

    def boundaries(self) -> list[dict]:
        """The current spec's boundary results (see :meth:`iter_rows`)."""
        if not self.boundary.is_dir():
            return []
        keep = self._current("boundaries")
        out = [self.read_boundary(p.stem) for p in sorted(self.boundary.glob("*.json"))
               if keep is None or p.stem in keep]
        return [b for b in out if b is not None]

    def table(self, volatile: bool = True):
        """All rows as a ``pandas.DataFrame`` sorted by key (``volatile=False`` drops the
        timing/host columns :data:`VOLATILE`, which differ between two runs of a case)."""
        import pandas as pd

        df = pd.DataFrame(list(self.iter_rows()))
        if len(df):
            df = df.sort_values("key").reset_index(drop=True)
            df = df[sorted(df.columns)]
            if not volatile:
                df = df.drop(columns=[c for c in VOLATILE if c in df.columns])
        return df

    def export(self) -> Path:
        """Write the table to ``table.parquet`` if pyarrow is installed, else to ``table.nc``
        (netCDF4/HDF5, dimension ``key``) and ``table.csv``; each atomically. Returns the
        Parquet or netCDF path."""
        df = self.table()
        self.root.mkdir(parents=True, exist_ok=True)
        try:
            import pyarrow  # noqa: F401

            kinds = ["parquet"]
        except ModuleNotFoundError:
            kinds = ["nc", "csv"]
        for kind in kinds:
            path = self.root / f"table.{kind}"
            if kind == "parquet":
                atomic_write(path, lambda tmp: df.to_parquet(tmp, index=False))
            elif kind == "csv":
                atomic_write(path, lambda tmp: df.to_csv(tmp, index=False))
            else:
                atomic_write(path, lambda tmp: _to_netcdf(df, tmp))
        return self.root / f"table.{kinds[0]}"


def _to_netcdf(df, path):
    """Rows -> netCDF: dimension ``key``; object columns of bools/None become float 1/0/nan,
    other object columns strings ("" for None)."""
    import numpy as np
    import xarray as xr

    d = df.copy()
    for c in d.columns:
        if d[c].dtype == object:
            vals = [v for v in d[c] if v is not None and not (isinstance(v, float) and math.isnan(v))]
            if vals and all(isinstance(v, bool) for v in vals):
                d[c] = [np.nan if v is None else float(v) for v in d[c]]
            else:
                d[c] = ["" if v is None else str(v) for v in d[c]]
    if "key" in d.columns:
        d = d.set_index("key")
    from flagwrap.io.runfile import checksummed

    ds = xr.Dataset.from_dataframe(d)
    ds.to_netcdf(path, engine="h5netcdf", encoding=checksummed(ds))
