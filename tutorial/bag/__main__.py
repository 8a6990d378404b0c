"""``python -m tutorial.bag``: the same as ``rtt-bag``."""

import sys

from tutorial.bag.cli import main

sys.exit(main())
