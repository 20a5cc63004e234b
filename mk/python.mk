# SPDX-License-Identifier: GPL-3.0-or-later
# The project's Python environment: build/venv, from requirements.txt (PyPI). Used by
# make bench (the peers), make mavlink (mavgen), make view and the Python tests.
# Included by mk/build.mk; the stamp is a copy of requirements.txt, so editing the list
# re-runs pip and nothing else does.

VENV       := $(BUILD)/venv
VENV_PY    := $(VENV)/bin/python
VENV_STAMP := $(VENV)/.requirements

.PHONY: venv
venv: $(VENV_STAMP)

$(VENV_STAMP): requirements.txt
	@echo "# creating $(VENV) from requirements.txt (PyPI; once)"
	@[ -x $(VENV_PY) ] || python3 -m venv $(VENV) || \
	  { echo "make venv: python3 -m venv failed (Debian: apt-get install python3-venv)"; exit 1; }
	@$(VENV_PY) -m pip install -q --disable-pip-version-check -r requirements.txt || \
	  { echo "make venv: pip install failed (PyPI must be reachable); run make again to retry"; exit 1; }
	@cp requirements.txt $@
