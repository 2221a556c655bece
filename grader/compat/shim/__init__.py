"""Directory the layer puts first on `sys.path` so that `import gym` finds the classic-API shim.

It is a package only so that installers ship the files below it; nothing imports it by this name.
"""
