from . import run


run()
