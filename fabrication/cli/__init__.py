"""The `onestroke` command line: a thin click layer over the library.

Each command lives in its own module (`vectorize_cmd.py`, `embroider_cmd.py`, ...) and is
registered below; shared options live in `options.py`. Every failure becomes a one-line
message and the exit code its class carries (`onestroke.errors`): 2 when the request was
wrong before any work (`InputError`, a bad option), 1 when the work failed (the disk, a
machine, memory), 130 when interrupted (Ctrl-C, SIGTERM, SIGHUP); never a traceback.
"""

# Ctrl-C while Python imports click, numpy and the rest would print a traceback: until the
# command runs, an interrupt (Ctrl-C, SIGTERM, SIGHUP) just says so and exits 130 (nothing
# has been written yet). `_signal` is the built-in C module (`signal` itself spends ~10 ms
# building enums).
import _signal
import os


def _interrupted_early(signum, frame) -> None:
    os.write(2, b"interrupted\n")
    os._exit(130)


if _signal.getsignal(_signal.SIGINT) is _signal.default_int_handler:  # keep SIG_IGN of background jobs
    _signal.signal(_signal.SIGINT, _interrupted_early)
for _signum in (_signal.SIGTERM, _signal.SIGHUP):
    if _signal.getsignal(_signum) == _signal.SIG_DFL:  # keep SIG_IGN (nohup)
        _signal.signal(_signum, _interrupted_early)

import errno  # noqa: E402 - after the Ctrl-C handler on purpose
import signal  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402

import click  # noqa: E402

from onestroke.errors import EXIT_BAD_REQUEST, EXIT_FAILED, EXIT_INTERRUPTED, Interrupted, OnestrokeError  # noqa: E402

MAX_MESSAGE = 500  # characters: a message quoting a huge value is cut in the middle

_OS_HINTS = {
    errno.ENOSPC: "the disk is full",
    errno.EDQUOT: "the disk quota is exceeded",
    errno.EROFS: "the file system is read-only",
    errno.EACCES: "permission denied",
    errno.EPERM: "operation not permitted",
    errno.ENOTDIR: "a part of the path is a file, not a folder",
    errno.EISDIR: "it is a folder",
    errno.ENOENT: "no such file or folder",
    errno.ENAMETOOLONG: "the file name is too long",
    errno.EIO: "input/output error",
}


def one_line(message: str) -> str:
    """`message` on one line of at most MAX_MESSAGE characters."""
    text = " ".join(str(message).split())
    if len(text) > MAX_MESSAGE:
        text = text[: MAX_MESSAGE - 205] + " ... " + text[-200:]
    return text


def describe_os_error(error: OSError) -> str:
    """An OSError as one sentence: what failed, on which file."""
    reason = _OS_HINTS.get(error.errno) or error.strerror or type(error).__name__
    name = error.filename if error.filename is not None else None
    return f"{reason}: {name!s}" if name is not None else reason


def _interrupt(signum, frame) -> None:
    """Ctrl-C, SIGTERM, SIGHUP: raise `KeyboardInterrupt` (`Interrupted` naming the signal)."""
    if _importing_or_finalizing(frame):
        # raised inside an import or a finalizer, the exception could be dropped (printed by
        # importlib's module-lock callback or a finalizer; swallowed by a library's optional
        # import, `except Exception` around a class body that wraps it in RuntimeError) and
        # the work go on: the same signal again in a moment, once that is over
        import threading

        threading.Timer(0.02, os.kill, (os.getpid(), signum)).start()
        return
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Interrupted(signal.Signals(signum).name)


def _importing_or_finalizing(frame) -> bool:
    """True when `frame` runs inside an import (importlib's frames below it) or a `__del__`."""
    while frame is not None:
        code = frame.f_code
        if code.co_filename.startswith("<frozen importlib") or code.co_name == "__del__":
            return True
        frame = frame.f_back
    return False


def _caused_by_ctrl_c(error: BaseException) -> KeyboardInterrupt | None:
    """The KeyboardInterrupt in `error`'s chain of causes, if any (a Ctrl-C landing while
    numpy defines a class comes out as "RuntimeError: Error calling __set_name__")."""
    seen = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, KeyboardInterrupt):
            return error
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return None


class OnestrokeGroup(click.Group):
    """A click group that turns every error into a one-line message and an exit code."""

    def invoke(self, ctx: click.Context):
        # From here on Ctrl-C raises KeyboardInterrupt, so atomic writes clean up; a kill or a
        # closed terminal does the same (temporary files removed, a batch's workers stopped and
        # its report written); SIG_IGN (background jobs, nohup) is kept
        taken = {}
        for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            if signal.getsignal(signum) in (signal.SIG_DFL, signal.default_int_handler, _interrupted_early):
                try:
                    taken[signum] = signal.signal(signum, _interrupt)
                except ValueError:  # invoked outside the main thread (a test): leave them
                    break
        warnings.simplefilter("ignore", RuntimeWarning)  # numpy's overflow/divide chatter
        try:
            return super().invoke(ctx)
        except OnestrokeError as error:
            self._fail(str(error), error.exit_code)
        except click.exceptions.UsageError as error:
            name = error.ctx.command_path if error.ctx is not None else "onestroke"
            self._fail(f"{error.format_message()} (see '{name} --help')", EXIT_BAD_REQUEST)
        except (click.exceptions.Exit, click.exceptions.Abort, SystemExit):
            raise
        except KeyboardInterrupt as error:
            click.echo(f"interrupted{f' ({error})' if isinstance(error, Interrupted) else ''}", err=True)
            sys.exit(EXIT_INTERRUPTED)
        except MemoryError:
            self._fail("out of memory; try a smaller image or design", EXIT_FAILED)
        except OSError as error:
            self._fail(describe_os_error(error), EXIT_FAILED)
        except RecursionError:
            self._fail("the input is nested too deeply to read", EXIT_BAD_REQUEST)
        except Exception as error:  # noqa: BLE001 - a bug still gets one line, and a way to report it
            interrupt = _caused_by_ctrl_c(error)
            if interrupt is not None:  # Python wraps an interrupt in a class body (an import) in RuntimeError
                click.echo(f"interrupted{f' ({interrupt})' if isinstance(interrupt, Interrupted) else ''}", err=True)
                sys.exit(EXIT_INTERRUPTED)
            self._fail(f"internal error ({type(error).__name__}: {error}); please report this with the "
                       "command line and input", EXIT_FAILED)
        finally:  # Python's own handling again (a program that invoked the group goes on)
            for signum, previous in taken.items():
                if previous is _interrupted_early:
                    previous = signal.default_int_handler if signum == signal.SIGINT else signal.SIG_DFL
                signal.signal(signum, previous)

    @staticmethod
    def _fail(message: str, code: int) -> None:
        click.echo(f"error: {one_line(message)}", err=True)
        sys.exit(code)


# Commands by name, in the order --help lists them; a command's module is imported only when
# that command runs (or --help lists them), so start-up pays for no other command's imports.
COMMANDS = {
    "vectorize": "fabrication.cli.vectorize_cmd:vectorize",
    "embroider": "fabrication.cli.embroider_cmd:embroider",
    "laser": "fabrication.cli.laser_cmd:laser",
    "batch": "fabrication.cli.batch_cmd:batch",
    "stream": "fabrication.cli.stream_cmd:stream",
    "preview": "fabrication.cli.preview_cmd:preview",
    "studio": "fabrication.cli.studio_cmd:studio",
    "ports": "fabrication.cli.ports_cmd:ports",
    "inkscape": "fabrication.cli.inkscape_cmd:inkscape",
    "emulator": "fabrication.cli.stream_cmd:emulator",
    "train-classifier": "fabrication.cli.train_cmd:train_classifier",
    "validate-classifier": "fabrication.cli.train_cmd:validate_classifier",
    "train-pass-scorer": "fabrication.cli.train_cmd:train_pass_scorer",
}


class LazyGroup(OnestrokeGroup):
    """Imports a command's module when the command is looked up, not at start-up."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return list(COMMANDS) + [name for name in super().list_commands(ctx) if name not in COMMANDS]

    def get_command(self, ctx: click.Context, name: str):
        if name in COMMANDS and name not in self.commands:
            import importlib

            from fabrication.cli.heap import loading_for_good

            module, attribute = COMMANDS[name].split(":")
            with loading_for_good():  # numpy and the rest it brings (fabrication/cli/heap.py)
                self.add_command(getattr(importlib.import_module(module), attribute), name)
        return super().get_command(ctx, name)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="onestroke")
def main() -> None:
    """Turn line drawings into embroidery files and laser G-code."""
