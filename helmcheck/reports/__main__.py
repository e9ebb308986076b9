"""``python -m helmcheck.reports DIR [--format html,junit,md] [--compare OLD_DIR]``."""

import sys

from .render import main

sys.exit(main())
