"""``python -m stage_sim.cli``: the ``stage_sim`` console script."""

import sys

from stage_sim.cli import main

sys.exit(main())
