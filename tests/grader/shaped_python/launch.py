"""Start of every process of a shaped interpreter: apply the shape, then run the command as python would.

The shaped interpreter's `bin/python` is a shell script running the real interpreter as
``python -S launch.py SHAPE ARGS...`` (with its own path as argv[0], so that `sys.executable` is the
script and every child of the run, the sandbox's bootstrap started with ``-S`` included, goes through
here too). This file applies `shapes.SHAPE` before anything else is imported, then does what the real
interpreter does with ARGS: the options the project uses (-S -B -I -E -s -P -u -q -X -W), then
``-c CODE``, ``-m MODULE`` or a script, with site initialisation unless -S.
"""

import os
import sys

_HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, _HERE)
import shapes  # noqa: E402

del sys.path[0]
shape_name, *arguments = sys.argv[1:]
shapes.SHAPES[shape_name]()

no_site = isolated = no_script_dir = unbuffered = False
while arguments and arguments[0].startswith("-") and arguments[0] != "-":
    option = arguments.pop(0)
    if option in ("-c", "-m"):
        break
    if option in ("-X", "-W"):
        arguments.pop(0)
        continue
    for letter in option[1:]:
        if letter == "S":
            no_site = True
        elif letter == "B":
            sys.dont_write_bytecode = True
        elif letter == "I":
            isolated = no_script_dir = True
        elif letter == "P":
            no_script_dir = True
        elif letter == "u":
            unbuffered = True
    continue
else:
    option = None

if isolated:
    extra = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    sys.path[:] = [p for p in sys.path if p not in extra]
del sys.path[0]  # launch.py's own directory
if not no_site:
    import site

    if isolated:
        site.ENABLE_USER_SITE = False
    site.main()
if unbuffered:
    for stream in (sys.stdout, sys.stderr):
        stream.reconfigure(write_through=True)

import runpy  # noqa: E402

if option == "-c":
    code, *rest = arguments
    sys.argv = ["-c", *rest]
    if not no_script_dir:
        sys.path.insert(0, "")
    namespace = {"__name__": "__main__", "__builtins__": __builtins__}
    exec(compile(code, "<string>", "exec"), namespace)
elif option == "-m":
    module, *rest = arguments
    sys.argv = [module, *rest]
    if not no_script_dir:
        sys.path.insert(0, os.getcwd())
    runpy.run_module(module, run_name="__main__", alter_sys=True)
else:
    script, *rest = arguments
    sys.argv = [script, *rest]
    if not no_script_dir:
        sys.path.insert(0, os.path.dirname(os.path.abspath(script)))
    runpy.run_path(script, run_name="__main__")
