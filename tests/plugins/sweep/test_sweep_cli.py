"""``masonryfw sweep`` on an existing cluster and ``masonryfw archive`` (write, verify, tampering).

References: the cluster's own worker count before and after (it must be left
running), the files on disk, and hand-made damage to an archive that --verify
must list file by file.
"""
from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from masonryfw.cli import cli

PARAM = "supports.settling.start=0.5:0.7:0.1"


@pytest.fixture(scope="module")
def swept(cluster, tmp_path_factory):
    """A 3-point sweep written by the CLI on the session cluster, with its folder."""
    folder = tmp_path_factory.mktemp("cli")
    out = folder / "study.nc"
    result = CliRunner().invoke(cli, ["sweep", "test-12c", "--plugin", "la", "--param", PARAM, "--scheduler",
                                      cluster.scheduler_address, "-o", str(out), "--no-progress"])
    assert result.exit_code == 0, result.output
    return folder, out, result


def test_the_cli_writes_one_dataset_and_leaves_the_cluster_running(swept, client):
    folder, out, result = swept
    assert "3 point(s), 3 solved or reused (0 from the store), 0 failed" in result.output
    sweep = xr.open_dataset(out)  # plain xarray reads it
    assert sweep.status.dims == ("supports_settling_start",)
    np.testing.assert_allclose(sweep.supports_settling_start.values, [0.5, 0.6, 0.7], rtol=0, atol=1e-15)
    assert sweep.attrs["sweep_command"].startswith("masonryfw sweep test-12c --plugin la")
    assert all((folder / p).is_file() for p in sweep.result_path.values)
    assert (folder / "study.store" / "results").is_dir()
    assert len(client.scheduler_info()["workers"]) == 2
    assert client.submit(sum, [1, 2]).result() == 3


def test_an_unknown_key_fails_before_any_work(cluster, tmp_path):
    out = tmp_path / "never.nc"
    result = CliRunner().invoke(cli, ["sweep", "test-12c", "--plugin", "la", "--param", "supports.settlng.start=0.5",
                                      "--scheduler", cluster.scheduler_address, "-o", str(out)])
    assert result.exit_code == 1
    assert "supports.settlng" in result.output
    assert list(tmp_path.iterdir()) == []  # no output, no store


def test_workers_and_scheduler_are_exclusive(cluster):
    result = CliRunner().invoke(cli, ["sweep", "test-12c", "--plugin", "la", "--param", PARAM,
                                      "--scheduler", cluster.scheduler_address, "--workers", "2"])
    assert result.exit_code == 2


def test_an_archive_verifies_and_serves_as_a_store(swept, cluster, tmp_path):
    folder, out, _ = swept
    archive = tmp_path / "archive"
    runner = CliRunner()
    assert runner.invoke(cli, ["archive", str(archive), "--from", str(out)]).exit_code == 0
    manifest = json.loads((archive / "MANIFEST.json").read_text())
    assert manifest["commands"]["sweep"].startswith("masonryfw sweep test-12c")
    assert manifest["commands"]["archive"].startswith("masonryfw archive")
    names = set(manifest["files"])
    assert {"sweep.nc", "specs/sweep.toml", "environment.json", "README.md"} <= names
    assert sum(n.startswith("results/") and n.endswith(".nc") for n in names) == 3
    assert sum(n.startswith("models/") for n in names) == 3 and sum(n.startswith("specs/") for n in names) == 4
    assert "dask" in json.loads((archive / "environment.json").read_text())["packages"]
    archived = xr.open_dataset(archive / "sweep.nc")
    assert all((archive / p).is_file() for p in archived.result_path.values)

    verified = runner.invoke(cli, ["archive", "--verify", str(archive)])
    assert verified.exit_code == 0, verified.output

    again = runner.invoke(cli, ["sweep", "test-12c", "--plugin", "la", "--param", PARAM, "--scheduler",
                                cluster.scheduler_address, "-o", str(tmp_path / "again.nc"), "--store", str(archive)])
    assert "(3 from the store)" in again.output
    assert runner.invoke(cli, ["archive", "--verify", str(archive)]).exit_code == 0  # nothing was written


def test_verify_lists_every_mismatch(swept, tmp_path):
    _, out, _ = swept
    archive = tmp_path / "archive"
    runner = CliRunner()
    assert runner.invoke(cli, ["archive", str(archive), "--from", str(out)]).exit_code == 0
    result_file = sorted((archive / "results").glob("*.nc"))[0]
    data = bytearray(result_file.read_bytes())
    data[-100] ^= 0xFF
    result_file.write_bytes(bytes(data))
    model_file = sorted((archive / "models").glob("*.nc"))[0]
    model_file.unlink()
    (archive / "notes.txt").write_text("added later")

    verified = runner.invoke(cli, ["archive", "--verify", str(archive)])
    assert verified.exit_code == 1
    lines = verified.output
    assert f"results/{result_file.name}: SHA-256 differs from the manifest" in lines
    # Damaged bytes either break the HDF5 structure or change the data: either way the file is named.
    assert (f"results/{result_file.name}: does not reopen" in lines
            or f"results/{result_file.name}: does not match its record" in lines)
    assert f"models/{model_file.name}: missing" in lines
    assert "notes.txt: not in the manifest" in lines
    assert "4 mismatch(es)" in lines


def test_archive_refuses_a_non_empty_target_and_needs_a_mode(swept, tmp_path):
    _, out, _ = swept
    (tmp_path / "taken").mkdir()
    (tmp_path / "taken" / "file").write_text("x")
    runner = CliRunner()
    refused = runner.invoke(cli, ["archive", str(tmp_path / "taken"), "--from", str(out)])
    assert refused.exit_code == 1 and "not an empty folder" in refused.output
    assert runner.invoke(cli, ["archive", str(tmp_path / "new")]).exit_code == 2
