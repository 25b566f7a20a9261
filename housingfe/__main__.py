from housingfe.cli import main

# mpi4py.futures workers import the parent's main module (as "__worker__"): without the guard each ran the CLI
if __name__ == "__main__":
    raise SystemExit(main())
