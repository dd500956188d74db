"""rockfrag.report.numbers - how the report prints a number, and the ledger of the facts it printed.

Input : values from the answer objects and result files (probabilities, intensities, counts).
Output: their text under one precision policy, and ``Facts``, the ledger of every fact a page printed (the
        quantity, what it is of, and its text), which the one-number test reads.

The precision policy, applied here and nowhere else:

- a probability (or a share of records or runs) to two significant figures, both printed ("0.40%", "2.0%"),
  "< 0.1%" below 0.1%, "0%" for none, "100%" for all, "> 99%" just below all (two figures would round it to a
  certainty);
- a computed intensity to two significant figures ("0.54 g"); a dispersion β to two decimals ("0.50");
- an input as the study states it (``as_stated``: "0.35", "50 years"; ``stated_probability``: a limit "1%");
- a calibrated model parameter (the bed's damping ratio fitted to a restitution) is not printed for the client.
"""

from __future__ import annotations

import math
from collections import defaultdict
from contextlib import contextmanager
from dataclasses import dataclass, field

FLOOR = 0.001
"""Below this probability the report prints "< 0.1%": no study of a few dozen records supports more digits."""


def probability(value) -> str:
    """A probability or share in percent: 2 significant figures, "< 0.1%" below ``FLOOR``, "-" when unknown.

    Parameters
    ----------
    value : float or None
        A probability in [0, 1].

    Returns
    -------
    str
        "12%", "2.3%", "2.0%", "0.21%", "0.40%", "< 0.1%", "0%", "> 99%", "100%" or "-".
    """
    if value is None or not math.isfinite(float(value)):
        return "-"
    value = float(value)
    if value <= 0:
        return "0%"
    if value >= 1:
        return "100%"
    if value < FLOOR:
        return "< 0.1%"
    shown = float(f"{100 * value:.2g}")
    if shown >= 100:
        return "> 99%"
    return _percent(shown)


def _percent(shown: float) -> str:
    """A percentage already rounded to two significant figures, printed with both ("0.40%", "2.0%", "12%")."""
    decimals = max(0, 1 - math.floor(math.log10(shown)))
    return f"{shown:.{decimals}f}%"


def bound(value, side: str) -> str:
    """A probability that is a bound: "< 0.81%" (at most) or "≥ 61%" (at least); a certainty prints as itself.

    ``side`` is "<" or "≥". The two significant figures are rounded away from the bound's safe side: an upper
    bound up, a lower bound down (0.197 prints "≥ 19%", never "≥ 20%", which the value does not reach). A lower
    bound of 1 is "100%"; an upper bound below ``FLOOR`` stays "< 0.1%".
    """
    text = probability(value)
    if text in ("-", "< 0.1%", "0%") or (side == "≥" and text == "100%"):
        return text
    percent = 100 * float(value)
    scale = 10 ** (math.floor(math.log10(percent)) - 1)  # the second significant figure's place
    steps = percent / scale
    steps = math.floor(steps + 1e-9) if side == "≥" else math.ceil(steps - 1e-9)
    shown = float(f"{steps * scale:.10g}")
    if side == "≥" and shown >= 99 and float(value) > 0.99:
        return "> 99%"  # as ``probability`` prints a share just below all
    return f"{side} {_percent(shown)}"


def stated_probability(value) -> str:
    """A probability the study states (a verdict's limit) in percent as stated: 0.01 -> "1%", 0.025 -> "2.5%"."""
    return f"{100 * float(value):.10g}%"


def intensity(value, unit: str) -> str:
    """A computed intensity to 2 significant figures, both printed, with its unit; "-" when unknown.

    "0.54 g", "0.60 g", "12 m/s": "0.6 g" beside "0.61 g" read as a coarser number (cold read 7).
    """
    if value is None or not math.isfinite(float(value)):
        return "-"
    return f"{two_figures(value)} {unit}".strip()


def two_figures(value) -> str:
    """A computed number to 2 significant figures, both printed: 0.6 -> "0.60", 2 -> "2.0", 12.3 -> "12"."""
    value = float(f"{float(value):.2g}")
    if value == 0:
        return "0"
    decimals = max(0, 1 - math.floor(math.log10(abs(value))))
    return f"{value:,.{decimals}f}"


def dispersion(value) -> str:
    """A lognormal dispersion β to two decimals ("0.50"); "-" when unknown."""
    if value is None or not math.isfinite(float(value)):
        return "-"
    return f"{float(value):.2f}"


def count(reached: int, total: int) -> str:
    """How many records of how many: "10 of 44"."""
    return f"{int(reached)} of {int(total)}"


def as_stated(value) -> str:
    """An input as the study states it: 0.35 -> "0.35", 50.0 -> "50", 2475.0 -> "2,475"."""
    value = float(value)
    return f"{value:,.0f}" if value.is_integer() else f"{value:g}"


def years(value) -> str:
    """A number of years as stated ("2,475 years")."""
    return f"{as_stated(value)} years"


@dataclass
class Facts:
    """The ledger of the facts the report printed: quantity and subject -> the texts and where they were printed.

    A page says a fact through ``say``; the same fact said twice must read the same (the one-number test).
    ``section`` names the page section being written (``writing``).
    """

    printed: dict = field(default_factory=lambda: defaultdict(list))
    section: str = ""

    def say(self, quantity: str, subject: tuple, text: str) -> str:
        """Record that the current section prints ``text`` for ``quantity`` of ``subject``; return ``text``."""
        self.printed[(quantity, tuple(map(str, subject)))].append((text, self.section))
        return text

    @contextmanager
    def writing(self, section: str):
        """The facts said inside this block are printed on ``section``."""
        before, self.section = self.section, section
        try:
            yield self
        finally:
            self.section = before

    def disagreements(self) -> dict:
        """Facts printed with more than one text: (quantity, subject) -> {text: [sections]}."""
        found = {}
        for key, said in self.printed.items():
            texts = {}
            for text, section in said:
                texts.setdefault(text, []).append(section)
            if len(texts) > 1:
                found[key] = texts
        return found


__all__ = ["FLOOR", "Facts", "as_stated", "bound", "count", "dispersion", "intensity", "probability", "years"]
