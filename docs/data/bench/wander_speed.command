taskset -c 0 python benchmarks/wander_speed.py --steps 300
