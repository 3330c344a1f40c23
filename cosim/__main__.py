"""``python -m arcosim`` is the same as the ``arcosim`` command."""

import sys

from arcosim.cli import main

sys.exit(main())
