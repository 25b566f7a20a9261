"""Ctrl-C in tests that interrupt a command they started."""
import signal


def interruptible():
    """preexec_fn of a command a test will interrupt: in the child before exec, SIGINT back to its default action.
    A process started with SIGINT ignored (any command run with `&` from a non-interactive shell, e.g. a CI job
    or a test suite started in the background) passes that on, and Python then keeps it ignored instead of raising
    KeyboardInterrupt -- as Unix intends for background jobs.  The user such a test stands for presses Ctrl-C in a
    terminal, where SIGINT is not ignored."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
