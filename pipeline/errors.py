"""rockfrag.errors - the exceptions a user of rockfrag can see.

Every error names what was wrong (file, line, field), the value found and what is allowed, so
that the CLI can print it as one line and exit non-zero without a traceback.
"""

from __future__ import annotations


class PipelineError(Exception):
    """Base class: a problem with the user's input or configuration, not a bug."""


class RecordError(PipelineError):
    """A strong-motion record cannot be read or fails a check.

    Parameters
    ----------
    path : str
        The file concerned.
    message : str
        What is wrong and what was expected.
    line : int, optional
        1-based line number in the file, where the problem is on one line.
    """

    def __init__(self, path, message, line=None):
        self.path = str(path)
        self.line = line
        self.reason = message
        where = f"{self.path}, line {line}" if line is not None else self.path
        super().__init__(f"{where}: {message}")

    def __reduce__(self):  # picklable, so errors cross process and dask boundaries intact
        return (type(self), (self.path, self.reason, self.line))


class ConfigError(PipelineError):
    """A configuration value (TOML file or argument) is missing or out of range.

    Parameters
    ----------
    field : str
        Dotted name of the field, e.g. ``processing.bandpass.order``.
    message : str
        What is wrong and the allowed range.
    source : str, optional
        The file the value came from.
    """

    def __init__(self, field, message, source=None):
        self.field = field
        self.source = source
        self.reason = message
        prefix = f"{source}: " if source else ""
        super().__init__(f"{prefix}{field}: {message}")

    def __reduce__(self):
        return (type(self), (self.field, self.reason, self.source))


class ManifestError(PipelineError):
    """The record catalogue does not match the files on disk (missing or changed files)."""


class SolverError(PipelineError):
    """A solver was called with parameters outside its range of validity."""
