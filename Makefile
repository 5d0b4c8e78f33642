# dolfinx_mortar: setup, demo, test, bench. Run `make help` for the targets.
# Everything runs with Debian's interpreter: the first python3 on PATH may be
# another one that cannot import DOLFINx.
PYTHON ?= /usr/bin/python3
BUILD_DIR ?= build
# A failure on one rank can leave the other waiting in a collective: the
# timeout turns such a hang into a failure instead of a stuck CI run.
MPIRUN ?= timeout 1800 mpirun -n 2 --oversubscribe
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
# Keep OpenMP/BLAS threads from fighting the MPI ranks on a 2-core machine.
export OMP_NUM_THREADS := 1

DEB_PACKAGES := python3-dolfinx libdolfinx-dev python3-basix python3-ufl \
	python3-ffcx python3-petsc4py python3-mpi4py python3-gmsh pybind11-dev \
	libeigen3-dev python3-pytest python3-matplotlib python3-scipy python3-tqdm \
	python3-dev cmake g++ make libgtest-dev openmpi-bin libopenblas0-serial python3-h5py
# libopenblas0-serial replaces the reference BLAS behind PETSc/MUMPS: 3.7x faster
# factorizations on Hertz 3D (33 s -> 8.8 s), serial so it does not fight MPI ranks.

# A second CPU's round-off: the serial suite runs again with OpenBLAS's kernels
# for another core type, so a test that depends on which side of zero
# round-off lands fails here rather than on a user's machine (a zero-length
# cell measures 5.6e-17 with SkylakeX kernels and 0 with Haswell's).
SECOND_CORETYPE ?= Haswell

.PHONY: help setup deps build install demo test test-cpp test-python test-mpi test-coretype bench bench-speed bench-scale stress clean

help:
	@echo "make setup  - install missing Debian packages, build the kernels, make dolfinx_mortar importable"
	@echo "make demo   - setup, then the main demo (Hertz 2D, figures 1 and 2) into results/"
	@echo "make test   - setup, then C++ tests (ctest), pytest, pytest under mpirun -n 2, and"
	@echo "              pytest again with another CPU's BLAS kernels (OPENBLAS_CORETYPE)"
	@echo "make bench  - setup, then the benchmarks in benchmarks/ (speed vs error: --quick)"
	@echo "make bench-speed - setup, then the full speed-vs-error study (~25 min, serial)"
	@echo "make bench-scale - setup, then Krylov iterations against h and penalty, and 1 against 2"
	@echo "              ranks, on Hertz 3D with two bodies (~1.5 h; docs/SCALING.md)"
	@echo "make stress - setup, then 1e6 generated slave-master pairs through 3D segmentation"

setup: deps build install

deps:
	@missing=""; for p in $(DEB_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" -ne 0 ]; then \
	    echo "Missing Debian packages. Run as root:"; \
	    echo "  apt-get update && apt-get install -y$$missing"; exit 1; \
	  fi; \
	  echo "Installing:$$missing"; \
	  apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q$$missing; \
	fi

build:
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE=$(PYTHON) > /dev/null
	cmake --build $(BUILD_DIR) -j2

# An editable install without pip: a .pth file that puts this checkout on
# Debian's interpreter's path (what `pip install -e` would do, minus the
# network and build isolation).
install:
	@site=$$($(PYTHON) -c "import site; print(site.getsitepackages()[0])"); \
	mkdir -p $$site && echo "$(CURDIR)" > $$site/dolfinx_mortar.pth; \
	cd / && $(PYTHON) -c "import dolfinx_mortar, sys; print('dolfinx_mortar importable from', dolfinx_mortar.__file__)"

demo: setup
	$(PYTHON) demos/hertz2d.py --json results/hertz2d.json --output results/hertz2d.xdmf
	$(PYTHON) demos/fig1_bases.py --json results/fig1_bases.json
	$(PYTHON) demos/fig2_sphere_nurbs.py --json results/fig2_pressures.json

test: setup test-cpp test-python test-mpi test-coretype

test-cpp:
	cd $(BUILD_DIR) && ctest --output-on-failure

test-python:
	$(PYTHON) -m pytest -q --color=no tests

test-mpi:
	$(MPIRUN) $(PYTHON) -m pytest -q --color=no -p no:cacheprovider tests

test-coretype:
	OPENBLAS_CORETYPE=$(SECOND_CORETYPE) $(PYTHON) -m pytest -q --color=no -p no:cacheprovider tests

bench: setup
	$(PYTHON) benchmarks/bench_basis_construction.py
	$(PYTHON) benchmarks/bench_segmentation.py
	$(PYTHON) benchmarks/speed_vs_error.py --quick

bench-speed: setup
	$(PYTHON) benchmarks/speed_vs_error.py

# docs/SCALING.md: the tables of the linear solvers
bench-scale: setup
	$(PYTHON) benchmarks/krylov_scaling.py --levels 0.5 1 2 --penalties 1e1 1e2 1e3 1e4 \
		--solvers block-fixed block direct
	$(PYTHON) benchmarks/krylov_scaling.py --levels 2 --penalties 1e3 --solvers block direct --tag n1
	$(MPIRUN) $(PYTHON) benchmarks/krylov_scaling.py --levels 2 --penalties 1e3 \
		--solvers block direct --tag n2

stress: setup
	$(BUILD_DIR)/kernels/stress_segmentation 1000000 1

clean:
	rm -rf $(BUILD_DIR) dolfinx_mortar/_kernels*.so
