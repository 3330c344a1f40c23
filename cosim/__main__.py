"""``python -m cosim`` is the same as the ``arcosim`` command."""

import sys

from cosim.cli import main

sys.exit(main())
