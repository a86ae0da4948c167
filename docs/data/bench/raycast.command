python benchmarks/raycast.py
