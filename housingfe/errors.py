"""Errors a user can act on. The CLI prints their message on one line and exits with code 2."""


class InputError(Exception):
    """Bad input: a malformed scene, an unknown key, a non-physical value, an unreadable file,
    a load a bearing cannot carry.  The message names the file and/or key."""


class SolverError(Exception):
    """A numerical failure the user must know about (incomplete eigen-solution, singular system)."""


class PoolError(InputError):
    """A pool of worker processes that did not start in time (e.g. MPI_Comm_spawn that never returns) or whose
    worker died while the command waited on it.  A thread of the pool stays blocked, so the process cannot end
    normally: the CLI prints the line and ends it at once."""
