python benchmarks/wander_sweep.py --core --world rooms.world --seeds 2 --minutes 30 --jobs 1
