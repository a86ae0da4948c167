taskset -c 0 python benchmarks/envs.py --worlds 16 64 --seconds 3 --episodes 3
