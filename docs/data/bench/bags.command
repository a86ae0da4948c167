python benchmarks/bags.py
