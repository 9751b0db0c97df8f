"""The two exception types: bad input given by its physical name, and bad input from the user.

The library raises :class:`ParameterError` (a ``ValueError``) with physical wording and the name of the
Python parameter at fault; only the command line translates that name into the option the user typed
(``roughpetsc.cli``) and turns it into a :class:`UserError`.
"""


class ParameterError(ValueError):
    """A parameter out of its range, named as the Python API names it.

    Parameters
    ----------
    parameter : str
        The API name of the parameter (``"E_star"``, ``"pstar"``, ``"rtol"``, ...).
    message : str
        What is wrong, in physical words, without an option name.
    """

    def __init__(self, parameter, message):
        super().__init__(message)
        self.parameter = parameter


class UserError(Exception):
    """Bad input from the user: an option, a file or a value.

    The command line prints the message (which names the option or file) and
    exits with status 2, without a traceback and without writing output files.
    """
