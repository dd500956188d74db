"""rockfrag.outputs - writing result files safely, netCDF files in one way.

Input : a destination path (and for ``write_dataset`` an xarray dataset). Output: ``atomic_path``, a
temporary path in the same folder that is renamed onto the destination only when writing succeeded, so a
crash never leaves a half-written file behind; ``write_dataset``, the one netCDF writer of the package
(atomic, compressed, CF-friendly), and ``netcdf_encoding``, the encoding it writes with.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path

import xarray as xr

NUMERIC_KINDS = "biuf"  # numeric dtypes (bool, int, float): strings are variable-length, take no filter
COMPLEVEL = 4  # zlib level: most of level 9's saving at a fraction of its time


@contextlib.contextmanager
def atomic_path(destination: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path; on success rename it to ``destination``, on error delete it.

    Parameters
    ----------
    destination : str or os.PathLike
        The file to write; its folder is created when missing.

    Yields
    ------
    pathlib.Path
        A new empty file in the destination's folder, to be written by the caller.
    """
    destination = Path(destination)
    destination.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(prefix=f".{destination.name}.", suffix=".part",
                                         dir=destination.parent)
    os.close(handle)
    try:
        yield Path(temporary)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(temporary, 0o666 & ~umask)  # mkstemp makes 0600; results are ordinary files
        os.replace(temporary, destination)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temporary)
        raise


def netcdf_encoding(dataset: xr.Dataset, compress: bool = True, complevel: int = COMPLEVEL) -> dict[str, dict]:
    """The per-variable netCDF encoding of every file the pipeline writes.

    Numeric data variables with at least one dimension are zlib-compressed (lossless: the values read
    back are the ones written). Dimension coordinates get no ``_FillValue``: CF coordinate variables
    hold no missing values, whereas xarray would otherwise give every float coordinate a NaN fill value.

    Parameters
    ----------
    dataset : xarray.Dataset
        The dataset to be written.
    compress : bool, optional
        Compress the numeric data variables (default True).
    complevel : int, optional
        zlib level from 1 to 9 (default 4).

    Returns
    -------
    dict
        ``{variable name: encoding}``, for ``xarray.Dataset.to_netcdf(encoding=...)``.
    """
    encoding: dict[str, dict] = {}
    if compress:
        for name, variable in dataset.data_vars.items():
            if variable.ndim and variable.dtype.kind in NUMERIC_KINDS:
                encoding[str(name)] = {"zlib": True, "complevel": complevel}
    for name in dataset.dims:
        if name in dataset.coords and dataset[name].dtype.kind in NUMERIC_KINDS:
            encoding[str(name)] = {"_FillValue": None}
    return encoding


def write_dataset(dataset: xr.Dataset, path: str | os.PathLike, *, compress: bool = True,
                  complevel: int = COMPLEVEL, encoding: Mapping[str, Mapping] | None = None) -> Path:
    """Write ``dataset`` as netCDF4 to ``path``: to a temporary file first, renamed when complete.

    Parameters
    ----------
    dataset : xarray.Dataset
        The result to write.
    path : str or os.PathLike
        The ``.nc`` file; its folder is created when missing, an existing file is replaced whole.
    compress : bool, optional
        zlib-compress the numeric data variables (default True).
    complevel : int, optional
        zlib level from 1 to 9 (default 4).
    encoding : mapping, optional
        Extra per-variable encoding, merged over :func:`netcdf_encoding`'s.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    Exception
        Whatever xarray or netCDF4 raise while writing; the temporary file is deleted and ``path`` is
        left as it was.
    """
    merged = netcdf_encoding(dataset, compress, complevel)
    for name, extra in (encoding or {}).items():
        merged[name] = {**merged.get(name, {}), **extra}
    path = Path(path)
    with atomic_path(path) as temporary:
        dataset.to_netcdf(temporary, engine="netcdf4", encoding=merged)
    return path
