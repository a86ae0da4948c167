python benchmarks/bags.py --duration 60 --repeat 1
