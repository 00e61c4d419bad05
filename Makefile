# The two set-up commands of the README:  make demo   and   make test
# Both install the Debian packages they need that are missing, configure
# and build.
PAPER_MODEL = models/3prru_paper.json
MODEL   ?= $(PAPER_MODEL)
# Each model builds in its own directory: build/ for the paper's, build-<file>
# for any other, so `make test MODEL=x.json` never mixes kernels.
BUILD   ?= $(if $(filter $(abspath $(MODEL)),$(abspath $(PAPER_MODEL))),build,build-$(basename $(notdir $(MODEL))))
RESULTS ?= results
PYTHON  ?= python3
FUZZ_SECONDS ?= 60

# Debian packages, per target: each installs only what it uses.
#   demo (and build, bench, compare-designs): the build (GSL; jansson,
#         found by pkg-config, for the model file loader), the plots and
#         the man pages (help2man; without it the build writes plain pages);
#   test: + g++ and clang (tests/test_dropin.sh), pkg-config (demo has it)
#         (tests/test_install.sh), MuJoCo (validation/), NumPy (the
#         Python binding's array path, python/tests), SymPy (the bench's
#         peer of the dynamics kernel, bench/sympy_peer.py), chromium and
#         Node.js with npm (prru view's page in a real browser,
#         tests/test_cli_view.sh; npm only when no npm command is there:
#         Debian's nodejs lacks it, NodeSource's has it and conflicts with
#         Debian's npm package), slurm-wlm and munge (a single-node Slurm
#         cluster that runs the docs' job-array example, tests/test_slurm.sh;
#         the test starts and stops its own daemons, not the system's),
#         the Arm cross compiler, newlib and QEMU (the controller kernels
#         built for and run on an emulated Cortex-M4, tests/test_mcu.sh);
#   test-asan: + valgrind (gcc's own sanitizers need nothing more);
#   fuzz: clang and its libFuzzer runtime, for the installed clang's version
#         (and the demo's, for the build whose generated kernels it links).
# cmake/debian_deps.sh installs the missing ones with apt-get as root or
# through sudo, else lists them with the command to run (exit 2).
# DEPS_DRY_RUN=1 shows what would be installed; SKIP_DEPS=1 skips the step.
DEPS_DEMO = cmake gcc make python3 libgsl-dev libjansson-dev pkg-config gnuplot-nox help2man
DEPS_TEST = $(strip $(DEPS_DEMO) g++ clang libmujoco-dev python3-numpy python3-sympy \
            chromium nodejs $(if $(shell command -v npm),,npm) slurm-wlm munge \
            gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm)
DEPS_ASAN = $(DEPS_TEST) valgrind
DEPS_FUZZ = clang clang-runtime libgsl-dev libjansson-dev pkg-config
DEPS_DRY_RUN ?=
SKIP_DEPS ?=
DEPS = PRRU_DEPS_DRY_RUN=$(DEPS_DRY_RUN) PRRU_SKIP_DEPS=$(SKIP_DEPS) bash cmake/debian_deps.sh

.PHONY: all deps deps-demo deps-test deps-asan deps-fuzz web-deps build demo compare-designs optimize-design test \
        docs-cli \
        test-asan fuzz check-generated regenerate bench clean
# Two package installations must never run at once (dpkg's lock); the
# compilers run in parallel inside cmake --build.
.NOTPARALLEL:

all: build

deps: deps-demo
deps-demo:
	@$(DEPS) demo $(DEPS_DEMO)
deps-test:
	@$(DEPS) test $(DEPS_TEST)
deps-asan:
	@$(DEPS) test-asan $(DEPS_ASAN)
deps-fuzz:
	@$(DEPS) fuzz $(DEPS_FUZZ)

build: deps-demo
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DPRRU_MODEL=$(abspath $(MODEL))
	cmake --build $(BUILD) -j 2

demo: build
	$(BUILD)/cli/prru paper --out $(RESULTS)
	$(BUILD)/cli/prru animate $(RESULTS)/paper_sim.csv --out $(RESULTS)/paper_run.gif
	$(MAKE) --no-print-directory compare-designs

# The paper's future work: three limbs (the paper's model) vs four
# (models/4prru.json), both on one build (--model).
compare-designs: deps-demo
	$(MAKE) --no-print-directory build MODEL=$(PAPER_MODEL) BUILD=build
	studies/compare_designs.sh build $(RESULTS)/compare

# The paper's purpose for w_R: optimise its b12, b3, l1, l2, a (+-20 %) over
# fig. 7's rectangle (also with the paper's slider travel, and with limb 3's
# lower link free), re-evaluate each written model by regenerating the
# kernels in a separate build, and the sensitivities (about three minutes).
PAPER_BUILD ?= build
optimize-design: deps-demo
	$(MAKE) --no-print-directory build MODEL=$(PAPER_MODEL) BUILD=$(PAPER_BUILD)
	studies/optimize_paper.sh $(PAPER_BUILD) $(RESULTS)/optimize

# CTEST_ARGS: more ctest options, e.g. -LE independent (tests/CMakeLists.txt).
test: deps-test build check-generated web-deps
	cd $(BUILD) && ctest --output-on-failure -j 2 $(CTEST_ARGS)

# The browser test's driver, playwright-core, and three.js (to check that
# web/vendor/three.module.min.js, which the build embeds, is the npm
# registry's three@0.170.0) at the versions web/package-lock.json pins,
# into web/node_modules; again only when the lock file changed. Without npm
# the step says so and tests/test_cli_view.sh skips (fails under CI=true).
web-deps: deps-test
	@if ! command -v npm >/dev/null 2>&1; then \
	  echo "make web-deps: npm not found: the browser test of prru view will be skipped"; \
	elif [ ! -f web/node_modules/.package-lock.json ] || \
	     [ web/package-lock.json -nt web/node_modules/.package-lock.json ]; then \
	  cd web && npm ci --ignore-scripts --no-audit --no-fund; \
	fi

# AddressSanitizer + UBSan build and ctest, fuzz corpus replay, valgrind on
# `prru paper` (own build directories; `make test` first for the Release one).
test-asan: deps-asan build
	RELEASE_BUILD=$(abspath $(BUILD)) tests/sanitize.sh

# libFuzzer over the number, table, load-schedule and scenario parsers.
fuzz: deps-fuzz build
	FUZZ_SECONDS=$(FUZZ_SECONDS) PRRU_GEN_DIR=$(abspath $(BUILD))/generated fuzz/run.sh

# Fails when the committed generated/ (the paper model's kernels and the
# topology kernels prru_p3_*, prru_p4_* and their variants prru_p3s_*,
# prru_p4s_* of every build) is not what the
# generator makes now, whichever MODEL the build uses.
# The committed set is whole: the opt-in derivative and regressor sets too.
TOPOLOGIES = 3 4
STRUCTURES = general simple
GEN_SETS = --derivatives --regressor
check-generated:
	@tmp=$$(mktemp -d) && \
	$(PYTHON) gen/prru_gen.py $(PAPER_MODEL) $(GEN_SETS) --out $$tmp --quiet && \
	for n in $(TOPOLOGIES); do for s in $(STRUCTURES); do \
	  $(PYTHON) gen/prru_gen.py --topology $$n --structure $$s --out $$tmp --quiet || \
	  { rm -rf $$tmp; exit 1; }; done; done && \
	if diff -r -q $$tmp generated >/dev/null; then echo "generated/ is up to date"; rm -rf $$tmp; \
	else diff -r -u generated $$tmp | head -40; rm -rf $$tmp; \
	  echo "generated/ is stale: run 'make regenerate' and commit"; exit 1; fi

regenerate:
	$(PYTHON) gen/prru_gen.py $(PAPER_MODEL) $(GEN_SETS) --out generated
	for n in $(TOPOLOGIES); do for s in $(STRUCTURES); do \
	  $(PYTHON) gen/prru_gen.py --topology $$n --structure $$s --out generated || exit 1; done; done

# docs/cli.md, the command-line reference, from the help texts of the
# paper model's build (tests/paper_cli_doc.sh fails when it is stale).
docs-cli: deps-demo
	$(MAKE) --no-print-directory build MODEL=$(PAPER_MODEL) BUILD=build
	$(PYTHON) docs/gen_cli.py build/cli/prru --out docs/cli.md

bench: build
	$(BUILD)/bench/prru_bench

clean:
	rm -rf $(BUILD)
