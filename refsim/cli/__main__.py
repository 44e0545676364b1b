"""``python -m refsim.cli``: the ``refsim`` command."""

import sys

from refsim.cli.app import main

sys.exit(main())
