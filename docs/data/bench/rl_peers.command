python benchmarks/rl_peers.py
