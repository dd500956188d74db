"""``python -m rockfrag`` runs the ``rockfrag`` command."""

import sys

from rockfrag.cli import main

sys.exit(main())
