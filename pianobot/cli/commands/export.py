"""The `pianobot export` command."""

from __future__ import annotations

from pathlib import Path

import typer

from pianobot.cli.terminal import out
from pianobot.errors import PianobotError


def export(
    model: Path = typer.Argument(
        ..., help="A trained policy's folder in the model store, e.g. models/<phrase hash>-<config hash>."
    ),
    output: Path = typer.Option(..., "--output", "-o", help="Write the policy to this .onnx file."),
):
    """Export a trained policy to ONNX (for a robot or any ONNX runtime); docs/models.md gives its inputs."""
    from pianobot.agent.export import export_onnx

    if output.suffix.lower() != ".onnx":
        raise PianobotError(f"-o {output}: the export is an ONNX file, name it *.onnx")
    if not model.is_dir():
        raise PianobotError(
            f"{model} is not a folder: give a trained policy's folder in the model store (see `pianobot inspect`)"
        )
    from pianobot.agent import store

    if store.kept_start(model):
        start = (store.read_manifest(model).get("start") or {}).get("path", "the general policy's folder")
        raise PianobotError(
            f"{model}: its training kept its start policy, so no policy of its own is stored (the general "
            f"policy plays the phrase): export that one, `pianobot export {start} -o {output}`"
        )
    export_onnx(model, output)
    out.print(f"policy {model.name} written to {output}")
