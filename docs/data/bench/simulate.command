python benchmarks/simulate.py --beams 240 --fov 240 --range 5.6 --kernels numba --threads 1 --robots 1 10 100 1000 --seconds 3
python benchmarks/simulate.py --beams 240 --fov 240 --range 5.6 --kernels numba --threads 2 --robots 1 10 100 1000 --seconds 3
python benchmarks/simulate.py --beams 240 --fov 240 --range 5.6 --kernels numpy --threads 1 --robots 1 100 --seconds 3
python benchmarks/simulate.py --beams 1081 --fov 270 --range 30 --kernels numba --threads 1 --robots 1 10 100 1000 --seconds 3
python benchmarks/simulate.py --beams 1081 --fov 270 --range 30 --kernels numba --threads 2 --robots 1 10 100 1000 --seconds 3
python benchmarks/simulate.py --beams 1081 --fov 270 --range 30 --kernels numpy --threads 1 --robots 1 100 --seconds 3
