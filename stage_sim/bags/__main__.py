"""``python -m stage_sim.bags STEPS REPORTS``: the bag writer process a recording starts
(:mod:`stage_sim.bags.writer`); STEPS and REPORTS are the file descriptors of its pipes."""

import sys

from stage_sim.bags.writer import main

main(sys.argv[1:])
