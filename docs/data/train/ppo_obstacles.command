python examples/train_ppo.py
