python benchmarks/startup.py
