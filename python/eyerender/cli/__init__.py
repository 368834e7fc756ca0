"""The command-line entry points, one module each: eyerecord (render a stage to images, like usdrecord; its farm
path is farm.py), eyestudy (speed versus error of the render plan) and eyeview (look-dev in the browser). Each has
`main(argv=None)` and runs with `python -m eyerender.cli.<name>`.
"""
