"""rockfrag_toy - a toy rockfrag plugin: what an installed package adds through rockfrag's entry points.

Input : nothing at import but rockfrag's own classes.
Output: three objects its ``pyproject.toml`` names as entry points (and two contact laws, the modules
``bed_linear`` and ``bed_hertz``, which it names too):

- ``A_RMS``, a ``rockfrag.measures.Measure``: the root-mean-square ground acceleration a_rms [m/s^2], shown in
  g; it scales with the record (exponent 1), so a study can scale its records to it; it has no RotD form (a
  study using it sets ``[intensity] component = "single"``) and neither pelicun nor OpenQuake knows it;
- ``ROCKING_08``, a ``rockfrag.damage_states.DamageState``: theta_max/alpha >= 0.8, judged by the verdict
  with a limit of 5% in the design life;
- ``TOY_FORMAT``, a ``rockfrag.records.RecordFormat``: a ``.toy`` file holds ``dt = <seconds>`` on its first
  line and one acceleration sample [m/s^2] per line after it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import obspy

from rockfrag.damage_states import DamageState
from rockfrag.measures import Measure
from rockfrag.records import RecordFormat
from rockfrag.units import STANDARD_GRAVITY


def root_mean_square(acceleration, dt, block, options) -> float:
    """a_rms = sqrt(mean(a^2)) [m/s^2] over the whole record (``dt``, ``block``, ``options`` unused)."""
    samples = np.asarray(acceleration, dtype=float)
    return float(np.sqrt(np.mean(samples ** 2)))


A_RMS = Measure(name="a_rms", function=root_mean_square, si_unit="m/s^2", display_unit="g",
                display_factor=STANDARD_GRAVITY, long_name="root-mean-square ground acceleration", label="a_rms",
                words="RMS acceleration")

ROCKING_08 = DamageState(name="rocking-0.8", edp="peak_angle_ratio", threshold=0.8,
                         description="theta_max/alpha >= 0.8 (close to overturning)", limit=0.05,
                         limit_source="the toy plugin's own limit (an example, not a published value)")


def is_toy(path) -> bool:
    """Whether ``path`` is a ``.toy`` record whose first line is ``dt = <seconds>``; never raises."""
    try:
        with open(path, encoding="utf-8") as file:
            return Path(path).suffix == ".toy" and file.readline().replace(" ", "").startswith("dt=")
    except (OSError, UnicodeDecodeError):
        return False


def read_toy(path, units=None, dt=None) -> obspy.Stream:
    """The record of a ``.toy`` file: one trace of acceleration [m/s^2] (``units`` and ``dt`` are in the file)."""
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    step = float(lines[0].split("=", 1)[1])
    samples = np.array([float(line) for line in lines[1:] if line.strip()])
    return obspy.Stream([obspy.Trace(samples, header={"delta": step, "station": Path(path).stem, "channel": "HN1"})])


TOY_FORMAT = RecordFormat(is_toy, read_toy)
