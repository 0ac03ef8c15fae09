# contactlink: `make demo` and `make test` work from a clean clone on Debian 12.
SHELL := /bin/bash
NP ?= 2
MPIRUN ?= mpirun --allow-run-as-root --oversubscribe
CARGO ?= cargo
# Debian's Python (python3-matplotlib is installed for it), not a pyenv shim.
PYTHON ?= /usr/bin/python3
# Local defaults; each can be overridden from the environment or the command
# line (e.g. on a cluster: make scaling OMPI_MCA_btl=self,vader,tcp;
# see docs/cluster.md).
OMPI_MCA_rmaps_base_oversubscribe ?= 1
OMPI_ALLOW_RUN_AS_ROOT ?= 1
OMPI_ALLOW_RUN_AS_ROOT_CONFIRM ?= 1
# Shared-memory transport only: a single machine with no usable network
# between ranks. Multi-node runs need a network transport here.
OMPI_MCA_btl ?= self,vader
OMPI_MCA_btl_vader_single_copy_mechanism ?= none
# The BTL message layer only: without it every rank also opens the network
# (MTL) transports, two of which spend 0.1 s each timing the clock at start-up
# (see src/runtime.rs). A cluster with InfiniBand or Omni-Path sets its own.
OMPI_MCA_pml ?= ob1
export OMPI_MCA_rmaps_base_oversubscribe OMPI_ALLOW_RUN_AS_ROOT OMPI_ALLOW_RUN_AS_ROOT_CONFIRM
export OMPI_MCA_btl OMPI_MCA_btl_vader_single_copy_mechanism OMPI_MCA_pml

# The executable cargo built for target KIND NAME, from cargo's JSON messages
# (not its human-readable output): $(call cargo_exe,KIND,NAME,CARGO ARGS).
cargo_exe = $$($(CARGO) $(3) --message-format=json | $(PYTHON) scripts/cargo_executable.py $(1) $(2))

.PHONY: deps build demo test test-mpi test-examples bench bench-peers work-precision scaling memory hertz-study ironing ironing-compare mortar-cost contact-cost friction-figures lint fmt clean

deps:
	@bash scripts/install-deps.sh

build: deps
	$(CARGO) build --release

demo: build
	@mkdir -p out
	$(MPIRUN) -n $(NP) target/release/contactlink run $(or $(SCENE),hertz-cylinder) -v -o out/demo.h5
	@echo "demo: results in out/demo.h5 (open out/demo.xmf in ParaView; h5ls -r out/demo.h5 lists it)"

# Every test: unit, verification and end-to-end (serial and mpirun -n 1/2/3),
# then the MPI harness under 2, 3 and 4 ranks, then the examples.
test: deps
	$(CARGO) build --release --bins --examples
	$(CARGO) test --release
	$(MAKE) --no-print-directory test-mpi
	$(MAKE) --no-print-directory test-examples

test-mpi:
	@set -e; bin=$(call cargo_exe,test,mpi,test --release --test mpi --no-run); \
	for n in 2 3 4; do \
	  echo "mpi-tests on $$n ranks"; \
	  $(MPIRUN) -n $$n $$bin; \
	done

# The examples of examples/, each serially (no mpirun) and on 2 ranks; each
# checks its own answer and exits with status 1 when it is wrong. Then the
# serial partition_balance on 2 and 4 ranks' partitions (under a second),
# and the Python example plots the Hertz pressure profile the Rust one wrote.
test-examples:
	@mkdir -p out/examples
	@set -e; \
	hertz=$(call cargo_exe,example,hertz_cylinder,build --release --example hertz_cylinder); \
	slide=$(call cargo_exe,example,block_slide,build --release --example block_slide); \
	gmsh=$(call cargo_exe,example,gmsh_mesh,build --release --example gmsh_mesh); \
	balance=$(call cargo_exe,example,partition_balance,build --release --example partition_balance); \
	echo "== example hertz_cylinder, serial, then 2 ranks"; \
	$$hertz 0.25 out/examples/hertz_cylinder-1.h5; \
	$(MPIRUN) -n 2 $$hertz 0.25 out/examples/hertz_cylinder-2.h5; \
	echo "== example block_slide, serial, then 2 ranks"; \
	$$slide 20 out/examples/block_slide-1.h5; \
	$(MPIRUN) -n 2 $$slide 20 out/examples/block_slide-2.h5; \
	echo "== example gmsh_mesh, serial, then 2 ranks"; \
	$$gmsh; \
	$(MPIRUN) -n 2 $$gmsh; \
	echo "== example partition_balance, 2 and 4 ranks' partitions (serial)"; \
	$$balance 2; \
	$$balance 4; \
	echo "== example plot_pressure.py"; \
	MPLBACKEND=Agg $(PYTHON) examples/plot_pressure.py out/examples/hertz_cylinder-2.h5

# Assembly throughput and solve time against DOFs; one contact solve against one
# plain elastic solve of the same mesh; what each reuse saves; 1 vs 2 ranks
# (CSV in bench-results/, tables in docs/tables/bench-*.md).
#
# Every benchmark target below writes its tables into docs/tables/ (through
# scripts/benchrun.py): re-running one replaces the figures it measured, with
# the date, machine, commit and command in the table's run line.
bench: deps
	@mkdir -p bench-results
	@set -e; bin=$(call cargo_exe,bench,assembly,bench --bench assembly --no-run); \
	for n in 1 2; do \
	  echo "assembly benchmark on $$n rank(s)"; \
	  $(MPIRUN) -n $$n $$bin | tee bench-results/assembly-$$n.csv || exit 1; \
	done
	@set -e; bin=$(call cargo_exe,bench,solve_costs,bench --bench solve_costs --no-run); \
	for n in 1 2; do \
	  echo "contact solve vs plain elastic solve, and what reuse saves, on $$n rank(s)"; \
	  $(MPIRUN) -n $$n $$bin | tee bench-results/solve-costs-$$n.csv || exit 1; \
	done
	@set -e; bin=$(call cargo_exe,bench,search,bench --bench search --no-run); \
	echo "contact search against slave points (serial)"; \
	$$bin | tee bench-results/search.csv
	$(PYTHON) scripts/bench_tables.py

# contactlink beside CalculiX (penalty surface-to-surface, one thread) on the
# same meshes: the graded Hertz line contact (Gmsh, h_c = b/5 ... b/40) and the
# built-in hertz-sphere mesh (h_c = 0.5 and 0.35): DOFs, wall time, Newton
# iterations, Hertz errors, the time ratio, and contactlink's contact solve
# against a plain elastic solve of the same mesh. One run each (REPEATS=3: the
# median of 3 for every line size). Installs gmsh and calculix-ccx if missing;
# about 19 minutes on 2 cores at load average 11-14, 14 of them the sphere
# (CalculiX alone 9 at h_c = 0.35). A subset, e.g.
#   make bench-peers PEERS="--cases sphere --sphere-sizes 0.5"
#   make bench-peers PEERS="--cases line --sizes 5,10"
bench-peers: build
	@bash scripts/install-deps.sh --peers
	@mkdir -p bench-results/peers
	@set -o pipefail; cd scripts/peers && $(PYTHON) -m unittest -q test_peers 2>&1 | tail -1
	$(PYTHON) scripts/bench_peers.py --np 1 --repeats $(or $(REPEATS),1) --sphere-repeats 1 $(PEERS)

# Run time against error for the Hertz line and point contacts: mesh size ×
# penalty × Uzawa tolerance, median of 3 runs each, CSV + PNG with the Pareto
# front in bench-results/ (about 5 minutes for the line contact, 15 for the
# point contact on 2 cores).
work-precision: build
	@mkdir -p bench-results
	$(PYTHON) scripts/work_precision.py --scene hertz-cylinder --np $(NP) --repeats 3
	$(PYTHON) scripts/work_precision.py --scene hertz-sphere --np $(NP) --repeats 3 \
	  --sizes 0.7,0.5 --penalties 0.1,1,10 --tols 1e-2,1e-3

# Strong scaling on the iterative path: hertz-sphere (167k DOFs, GMRES +
# GAMG) on 1 and 2 ranks, and the plain elastic solve of the same mesh (the
# machine's ceiling); one table with the Newton/Uzawa/KSP counts, solve and
# CPU seconds, T1/(P·TP), peak memory of the largest and smallest rank, work
# per rank and halo, then the time per phase and the headline lines (medians
# of 3 runs, 1 and 2 ranks alternating; a few minutes on a quiet 2-core
# machine). `python3 scripts/scaling.py --help` for the direct-path case and
# the 4-rank run.
scaling: build
	@mkdir -p bench-results
	$(PYTHON) scripts/scaling.py --repeats 3

# Peak memory per rank (largest, smallest) against the ranks: set-up only of a
# 1.28M-DOF mesh on 1, 2, 4, 8 ranks and a 167k-DOF plain elastic solve on
# 1, 2, 4; per rank count the largest and smallest rank's peak, their ratios
# to 1 rank, the largest peak less file-backed (library) pages, each phase's
# resident memory and the ratios against the targets (about 5 minutes on 2
# cores; the 8-rank set-up needs ~3 GB).
memory: build
	@mkdir -p bench-results
	$(PYTHON) scripts/memory.py --mpirun "$(MPIRUN)"

# Hertz verification under refinement (figures in docs/verification.md).
hertz-study: build
	@for args in "--set mesh.fine_size=0.2" "" "--set mesh.level=1 --set solver.direct_max_dofs=200000"; do \
	  echo "== hertz-cylinder $$args"; \
	  $(MPIRUN) -n 2 target/release/contactlink run hertz-cylinder $$args | grep -E "Hertz|done" ; \
	done
	@for args in "--set mesh.fine_size=0.5" ""; do \
	  echo "== hertz-sphere $$args"; \
	  $(MPIRUN) -n 2 target/release/contactlink run hertz-sphere $$args | grep -E "Hertz|done" ; \
	done

# Ironing (Puso & Laursen 2004 style): contact force history as CSV and PNG.
ironing: build
	@mkdir -p out
	$(MPIRUN) -n $(NP) target/release/contactlink run ironing -q -o out/ironing.h5
	$(PYTHON) scripts/plot_history.py out/ironing.csv out/ironing.png --pair ironing --mu 0.3 --title "ironing: die dragged over a soft slab (μ = 0.3)"

# Ironing with the links and with the mortar formulation: the die's force
# ratio |Fx|/|Fz| over the drag (mean, max - min, std) side by side
# (docs/tables/ironing.md).
ironing-compare: build
	@mkdir -p out
	$(MPIRUN) -n $(NP) target/release/contactlink run ironing -q -o out/ironing-links.h5 --set contact.formulation=links
	$(MPIRUN) -n $(NP) target/release/contactlink run ironing -q -o out/ironing-mortar.h5 --set contact.formulation=mortar
	$(PYTHON) scripts/ironing_ratio.py out/ironing-links.csv out/ironing-mortar.csv

# Mortar against links on the same scenes, alternated, median of REPEATS
# runs each, 1 rank (docs/tables/mortar-cost.md).
mortar-cost: build
	@mkdir -p out
	$(PYTHON) scripts/mortar_cost.py target/release/contactlink $(or $(REPEATS),3)

# Contact solve against the plain elastic solve of the same mesh: the graded
# line meshes on 1 and 2 ranks, the spheres (docs/tables/contact-cost.md;
# CASES="line mortar,sphere h=0.35 mortar" runs a subset and replaces only
# its rows).
contact-cost: build
	@bash scripts/install-deps.sh --peers
	$(PYTHON) scripts/bench_peers.py --cases line --dry-run --out bench-results/lines
	$(PYTHON) scripts/contact_cost.py target/release/contactlink $(or $(REPEATS),3) --cases "$(CASES)" --lines bench-results/lines

# The friction and dynamics figures of docs/verification.md (block-slide, ironing, impact).
friction-figures: ironing
	$(MPIRUN) -n $(NP) target/release/contactlink run block-slide -q -o out/block-slide.h5
	$(PYTHON) scripts/plot_history.py out/block-slide.csv out/block-slide.png --pair floor --mu 0.3 --title "block-slide (μ = 0.3)"
	$(MPIRUN) -n $(NP) target/release/contactlink run impact -q -o out/impact.h5
	$(MPIRUN) -n $(NP) target/release/contactlink run impact -q -o out/impact-friction.h5 --set contact.friction=0.3

# Formatting and clippy with every warning an error (CI runs it before the tests).
lint: deps
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --all-targets --release -- -D warnings

fmt:
	$(CARGO) fmt --all

clean:
	$(CARGO) clean
	rm -rf out
