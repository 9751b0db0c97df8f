"""The one exception type for bad user input."""


class UserError(Exception):
    """Bad input from the user: an option, a file or a value.

    The command line prints the message (which names the option or file) and
    exits with status 2, without a traceback and without writing output files.
    """
