"""``python -m torquesplit``: the command line, as the ``torquesplit`` command runs it
(where the command is not on the PATH: a user install, a virtual environment not
activated)."""

if __name__ == "__main__":
    from torquesplit._launch import main

    main()
