python benchmarks/startup.py --runs 1
