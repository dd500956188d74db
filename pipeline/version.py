"""rockfrag.version - the package version, alone, so that every layer can import it without the public API.

Output: ``__version__``, written into every result file's attributes and the report's provenance. The build reads
it from here (pyproject.toml: ``dynamic = ["version"]``): this is the one place it is written.
"""

__version__ = "0.1.0"
