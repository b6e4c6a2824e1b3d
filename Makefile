# Thin convenience wrapper around CMake/CTest. See README.md.
BUILD_DIR ?= build
# sanitizer build (AddressSanitizer + UndefinedBehaviorSanitizer): its own tree
SAN_BUILD_DIR ?= build-asan
SAN_JOBS ?= $(JOBS)
JOBS      ?= $(shell nproc)
CMAKE_FLAGS ?=
# OpenMPI refuses to run as root unless told; CI and containers run as root.
export OMPI_ALLOW_RUN_AS_ROOT=1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1
export OMP_NUM_THREADS=1
# Open MPI start-up of the runs started here (one node): the ob1 messaging layer
# with the self and shared-memory transports, no probing of network libraries
# (docs/scaling.md, "Start-up"); a value set in the environment is kept.
OMPI_MCA_pml ?= ob1
OMPI_MCA_btl ?= self,vader
export OMPI_MCA_pml OMPI_MCA_btl

.PHONY: all deps format configure build demo test verify verify-paper campaign composability sanitize bench clean

all: build

deps:
	@bash scripts/install-deps.sh

$(BUILD_DIR)/build.ninja: | deps
	cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

# rewrite every tracked .h/.cc with the root .clang-format (ctest style.clang_format checks it)
format: deps
	bash scripts/format.sh

configure: deps $(BUILD_DIR)/build.ninja

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

# the demo .prm sets `output/png snapshots = final`: the run ends by drawing its final deposit
demo: build
	@rm -f output/column_collapse_2d/png/snapshot_*.png
	$(BUILD_DIR)/tools/talus-explicit parameter_files/demo/column_collapse_2d.prm
	@png=$$(ls output/column_collapse_2d/png/snapshot_*.png 2>/dev/null | tail -n 1); \
	  if [ -n "$$png" ]; then echo "demo: the final deposit is drawn in $$png"; \
	  else echo "demo: no PNG of the final deposit was drawn (see the warning above)"; fi

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -LE "verify|bench|paper"

verify: build sanitize
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -L "fast|verify"
	$(MAKE) campaign

# Checks at a paper's full resolution that take hours (label "paper"); each run
# checkpoints and resumes, so the target can be stopped and started again.
verify-paper: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -L paper

# The verification campaign (issue 6, `make verify` only): convergence families,
# Courant sweeps, large-deformation and near-incompressible stress tests; regenerates
# docs/verification/README.md (+ csv/, png/) and checks it against the CSVs.
campaign: build
	python3 scripts/verify_campaign.py $(BUILD_DIR)
	cd $(BUILD_DIR) && ctest --output-on-failure -R "verification.readme_matches_csv"
	$(MAKE) -C parameter_files/campaigns BUILD=$(abspath $(BUILD_DIR))

# docs/composability.md: every explicit feature under every option set, run or refused
# (tests/verification/composability.py; ctest verification.composability_matrix checks it)
composability: build
	python3 tests/verification/composability.py $(BUILD_DIR)/tools/talus-explicit $(BUILD_DIR)/composability \
	  --write docs/composability.md

# Unit tests and short runs of every tool (plus the fast .prm fuzz subset) built
# with -DTALUS_SANITIZE=ON in $(SAN_BUILD_DIR); any ASan/UBSan report fails.
sanitize: deps
	cmake -S . -B $(SAN_BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release -DTALUS_SANITIZE=ON $(CMAKE_FLAGS)
	cmake --build $(SAN_BUILD_DIR) -j $(SAN_JOBS)
	cd $(SAN_BUILD_DIR) && ctest --output-on-failure -j $(SAN_JOBS) -L "unit|sanitize"

bench: build
	bash scripts/bench.sh $(BUILD_DIR)

clean:
	rm -rf $(BUILD_DIR) $(SAN_BUILD_DIR)
