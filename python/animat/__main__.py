"""``python -m animat``: see :mod:`animat.cli`."""

import sys

from .cli import main

sys.exit(main())
