"""The learning agent: Soft Actor-Critic, its hyperparameters, its replay buffer, and the model store of trained policies."""
