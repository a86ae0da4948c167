taskset -c 0 python benchmarks/worlds.py --seconds 2
