"""``python -m fpdtw.paper.claims verify figures/``: every verdict from the committed files."""

import sys

from fpdtw.paper.claims.verify import main

sys.exit(main())
