# Two entry points for a fresh machine (see README): `make demo` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin

.PHONY: demo test install examples clean

$(BIN)/pianobot: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet torch==2.13.0  # the local CPU wheel; must come before anything that needs torch
	$(BIN)/pip install --quiet -e ".[test]"
	touch $(BIN)/pianobot

install: $(BIN)/pianobot

demo: install
	mkdir -p out
	$(BIN)/pianobot play examples/midi/twinkle.mid -o out/twinkle.mid --video out/twinkle.mp4  # the policies in models/
	$(BIN)/pianobot score out/twinkle.mid examples/midi/twinkle.mid --no-notes --plot out/twinkle.png

test: install
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/python -m pytest

examples: install
	$(BIN)/python examples/make_examples.py

clean:
	rm -rf $(VENV) *.egg-info
