python benchmarks/fidelity.py
