"""The learning agent: Soft Actor-Critic and its replay buffer."""
