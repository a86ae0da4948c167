"""ament_python package definition: one tree that both `pip install` and `colcon build` install."""

from glob import glob

from setuptools import find_packages, setup

PACKAGE = "stage_sim"

# data_files paths are relative to the install prefix; glob is not recursive, so one entry per folder.
DATA_FOLDERS = ["worlds", "maps", "robots", "launch_scripts"]

setup(
    name=PACKAGE,
    version="0.1.0",
    description="A pure-Python stageros for ROS 2 (Stage worlds, kinematics, odometry error, laser ray casting)",
    license="Apache-2.0",
    python_requires=">=3.10",
    packages=find_packages(include=[PACKAGE, f"{PACKAGE}.*"]),
    # The browser view's page (HTML, JavaScript modules, CSS), served from the installed package.
    package_data={f"{PACKAGE}.view": ["page/*.html", "page/*.css", "page/js/*.js"]},
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        *[(f"share/{PACKAGE}/{folder}", glob(f"{folder}/*.*")) for folder in DATA_FOLDERS],
    ],
    install_requires=["setuptools", "numpy", "numba", "pyyaml", "pillow", "aiohttp", "foxglove-sdk==0.30.3", "mcap",
                      "rosbags"],
    extras_require={
        "test": ["pytest", "playwright", "mcap-ros2-support"],
        # Reinforcement-learning environments (stage_sim.envs); ray adds the scale-out example.
        "rl": ["gymnasium>=1.0", "pettingzoo>=1.24", "scipy"],
        "ray": ["gymnasium>=1.0", "pettingzoo>=1.24", "scipy", "ray>=2.9"],
        # PPO training (examples/train_ppo.py, `make train`): heavy, so in a venv of its own.
        "train": ["gymnasium>=1.0", "pettingzoo>=1.24", "scipy", "stable-baselines3>=2.3", "torch"],
    },
    zip_safe=False,
    entry_points={
        "console_scripts": [
            "stage_sim = stage_sim.cli:main",
            "stageros = stage_sim.ros.stageros_main:main",
            "teleop = stage_sim.ros.teleop:main",
            "wander = stage_sim.ros.wander:main",
        ],
    },
)
