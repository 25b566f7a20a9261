# The two commands of the README: `make demo` and `make test`. Each bootstraps a fresh machine first.
VENV ?= .venv
export OMPI_ALLOW_RUN_AS_ROOT = 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM = 1
export OPENBLAS_NUM_THREADS = 1
# pytest-xdist workers for `make test` ("auto": one per core); mpirun tests then share the cores with the other
# worker, so idle MPI ranks yield the core instead of spinning (same answers, docs/CONTRIBUTING.md).
TEST_WORKERS ?= auto
export OMPI_MCA_mpi_yield_when_idle = 1

.PHONY: bootstrap demo test bench container clean

bootstrap:
	@bash scripts/bootstrap.sh

# the main job: the Ch. 5 test gearbox's run-up, gear set -> L_WA over speed (~15 s on a quiet machine, README.md)
demo: bootstrap
	$(VENV)/bin/housingfe run test-gearbox-runup --out results/test-gearbox-runup

test: bootstrap
	$(VENV)/bin/python -m pytest -q --durations=25 -n $(TEST_WORKERS) --dist load tests

bench: bootstrap
	$(VENV)/bin/housingfe bench modal --out results/bench-modal

# Builds docker/Dockerfile (docker, else podman; offline-capable) and checks box-free in it against this machine.
container: bootstrap
	bash docker/build.sh --check $(CONTAINER_ARGS)

clean:
	rm -rf results .pytest_cache
