"""Directory the layer appends to `sys.path`: a minimal `IPython` used only when IPython is not installed.

It is a package only so that installers ship the files below it; nothing imports it by this name.
"""
