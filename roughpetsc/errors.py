"""The two exception types: bad input given by its physical name, and bad input from the user.

Only the command line translates a :class:`ParameterError`'s parameter into the option the user typed.
"""


class ParameterError(ValueError):
    """A parameter out of its range, named as the Python API names it.

    ``parameter``: its API name (``"E_star"``, ``"pstar"``, ...); ``message``: what is wrong, in physical words.
    """

    def __init__(self, parameter, message):
        super().__init__(message)
        self.parameter = parameter


class UserError(Exception):
    """Bad input from the user: an option, a file or a value.

    The command line prints the message and exits with status 2, without a traceback or output files.
    """
