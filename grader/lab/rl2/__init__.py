"""The second lab (Policy Function Iteration / Reinforcement Learning 2)."""
