"""Reference solutions to the second lab (Policy Function Iteration / RL 2), per edition."""
