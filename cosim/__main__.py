"""``python -m arcosim`` is the same as the ``arcosim`` command."""

import sys

from arcosim.cli import main

if __name__ == "__main__":
    sys.exit(main())
