"""``python -m pipeline`` runs the ``rockfrag`` command."""

import sys

from pipeline.cli import main

sys.exit(main())
