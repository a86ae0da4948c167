taskset -c 0 python benchmarks/envs.py --seconds 3 --episodes 3
