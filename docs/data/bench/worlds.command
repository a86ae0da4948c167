taskset -c 0 python benchmarks/worlds.py --seconds 2
python benchmarks/worlds.py --worlds rl --threads 2 --seconds 2
