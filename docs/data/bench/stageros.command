python benchmarks/stageros.py --seconds 5
