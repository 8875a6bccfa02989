"""The ``formation`` command installed with the package: the same program as the Rust binary
(its code is compiled into the native module), so ``formation animate ...`` behaves alike."""

import sys

from . import _native


def main() -> None:
    """Runs ``formation`` with the process's arguments and exits with its status."""
    sys.exit(_native.run_cli(sys.argv[1:]))


if __name__ == "__main__":
    main()
