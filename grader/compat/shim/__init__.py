"""Directory the layer puts first on `sys.path` so that `import gym` finds the classic-API shim.

It also holds the second lab's helper module under both its names, `model_free_RL` and `model_free_rl`.
It is a package only so that installers ship the files below it; nothing imports it by this name.
"""
