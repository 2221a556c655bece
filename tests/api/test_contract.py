"""The API keeps its OpenAPI contract: schemathesis finds nothing, with a student's or the instructor's token.

Every check (status codes, headers, content types and bodies against the schema, schema-valid requests
accepted and invalid ones refused, `Allow` on 405, authentication not ignored, resources reachable through
the documented links) in every phase, the stateful one included, against a real `gymgrade serve`.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from contract import ContractRun, caller_tokens, run_schemathesis, start_contract_server
from live_server import LiveProcess

pytestmark = [pytest.mark.e2e, pytest.mark.slow]

MAX_OUTPUT_CHARS = 20_000


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[LiveProcess]:
    process = start_contract_server(tmp_path_factory.mktemp("contract"))
    yield process
    process.stop()


@pytest.fixture(scope="module")
def tokens(server: LiveProcess) -> dict[str, str]:
    return caller_tokens(server)


@pytest.mark.parametrize("caller", ["student", "instructor"])
def test_schemathesis_finds_nothing(
    server: LiveProcess, tokens: dict[str, str], caller: str, tmp_path: Path
) -> None:
    run: ContractRun = run_schemathesis(server.url, caller, tokens[caller], tmp_path / "report.json")
    assert run.clean, (
        f"schemathesis as the {caller}: {run.failures} failing cases, {run.errors} errors, "
        f"phases {run.phases}, exit {run.exit_code}\n{run.output[-MAX_OUTPUT_CHARS:]}\n"
        f"server log:\n{server.log()}"
    )
    assert run.cases > 0
