taskset -c 0 python benchmarks/jump_chain.py
