"""Attacks on the tool's LTI side, played by a real platform (`lti1p3platform`, lti_platform.py) against
`gymgrade serve`: registration tickets replayed or opened by a GET, a configuration claiming another
issuer, endpoints and service URLs on other hosts, a loopback platform the operator did not allow, a huge
JWKS, launches with made-up key ids, another azp or target, a lab picker's form sent twice; and the
origins framing the tool set per platform."""

from __future__ import annotations

import html
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from api_testing import instructor_headers
from live_server import LiveProcess
from lti_platform import INSTRUCTOR, LEARNER, LaunchSpec, LtiPlatform, query_of
from lti_testing import ONE_PROBLEM, browser, landed, register, tool_environment, upload, wait

from api.errors import LtiRequestInvalid
from api.lti.platforms import PlatformRegistration

pytestmark = [pytest.mark.e2e, pytest.mark.slow]


@pytest.fixture(scope="module")
def tool(tmp_path_factory: pytest.TempPathFactory) -> Iterator[LiveProcess]:
    """`gymgrade serve` allowed to reach loopback platforms over http (as every LTI test's tool)."""
    directory = tmp_path_factory.mktemp("lti-hardened")
    env = tool_environment(
        directory / "data", lti_publish_seconds=0.2, lti_retry_seconds=0.2, lti_publish_attempts=2
    )
    server = LiveProcess("serve", env, directory / "serve.log").start()
    yield server
    server.stop()


@pytest.fixture
def lms() -> Iterator[LtiPlatform]:
    """A platform of the test's own, running."""
    with LtiPlatform().running() as running:
        yield running


def registration_url(tool: LiveProcess) -> str:
    made = httpx.post(tool.url + "/lti/registrations", headers=instructor_headers())
    assert made.status_code == 201, made.text
    url: str = made.json()["url"]
    return url


def configuration_url(lms: LtiPlatform) -> str:
    return lms.issuer + "/.well-known/openid-configuration"


def register_by_hand(tool: LiveProcess, lms: LtiPlatform) -> None:
    lms.register_tool(tool.url)
    response = httpx.post(
        tool.url + "/lti/platforms", json=lms.manual_registration, headers=instructor_headers()
    )
    assert response.status_code == 201, response.text


def foreign(lms: LtiPlatform) -> list[tuple[str, str]]:
    """The requests the platform received under another host name than its issuer's (localhost)."""
    return [(host, path) for host, path in lms.requests if host.startswith("localhost")]


def test_a_ticket_registers_once_on_a_post_and_stays_out_of_the_log(
    tool: LiveProcess, lms: LtiPlatform
) -> None:
    url = registration_url(tool)
    ticket = query_of(url)["ticket"]
    with browser() as client:
        # The platform's GET shows a form and does nothing: no configuration read, no registration, the
        # ticket left unused (a link previewer or prefetch opening the URL spends nothing).
        opened = client.get(
            tool.url + "/lti/register",
            params={
                "ticket": ticket,
                "openid_configuration": configuration_url(lms),
                "registration_token": "t0ken-of-lms",
            },
        )
        assert opened.status_code == 200 and 'action="/lti/register"' in opened.text
        assert lms.requests == [] and lms.registrations == []
        done = register(client, url, configuration_url(lms))
        assert done.status_code == 200, done.text
        assert len(lms.registrations) == 1
        replayed = register_post(client, tool, ticket, lms)
        assert replayed.status_code == 401
        assert "this registration URL was used already (a ticket registers one platform)" in replayed.text
        reopened = client.get(
            tool.url + "/lti/register",
            params={"ticket": ticket, "openid_configuration": configuration_url(lms)},
        )
        assert reopened.status_code == 401
    assert len(lms.registrations) == 1, "a used ticket registered a second platform"
    log = tool._log_path.read_text(encoding="utf-8")
    assert "GET /lti/register?ticket=[redacted]" in log
    assert ticket not in log and "t0ken-of-lms" not in log, "a credential was written to the access log"


def register_post(client: httpx.Client, tool: LiveProcess, ticket: str, lms: LtiPlatform) -> httpx.Response:
    return client.post(
        tool.url + "/lti/register",
        data={"ticket": ticket, "openid_configuration": configuration_url(lms), "registration_token": "x"},
    )


@pytest.mark.parametrize(
    ("configuration", "message"),
    [
        (
            # The configuration URL http://127.0.0.1:PORT/... starts with this string: a prefix match
            # accepted it, as https://canvas.instructure.com matched https://canvas.instructure.com.evil.tld.
            lambda lms: {"issuer": lms.issuer[:-1]},
            "names issuer {issuer!r}, whose origin (scheme, host and port) is not the configuration's",
        ),
        (
            lambda lms: {"registration_endpoint": lms.issuer.replace("127.0.0.1", "localhost") + "/register"},
            "the platform's registration_endpoint {registration_endpoint!r} is not on its issuer's origin",
        ),
        (
            lambda lms: {"jwks_uri": "http://169.254.169.254/latest/meta-data/jwks"},
            "the platform's jwks_uri {jwks_uri!r} is not on its issuer's origin",
        ),
        (
            lambda lms: {"token_endpoint": "ftp://127.0.0.1/token"},
            "the platform's token_endpoint: 'ftp://127.0.0.1/token' is not an https or http URL",
        ),
    ],
    ids=["issuer-prefix", "registration-endpoint-elsewhere", "jwks-on-metadata-address", "not-http"],
)
def test_a_configuration_claiming_another_issuer_or_foreign_endpoints_registers_nothing(
    tool: LiveProcess, lms: LtiPlatform, configuration: Any, message: str
) -> None:
    lms.configuration = configuration(lms)
    before = httpx.get(tool.url + "/lti/platforms", headers=instructor_headers()).json()
    with browser() as client:
        refused = register(client, registration_url(tool), configuration_url(lms))
    assert refused.status_code in (400, 502), refused.text
    assert message.format(**lms.configuration) in html.unescape(refused.text)
    assert lms.registrations == [] and foreign(lms) == []
    assert httpx.get(tool.url + "/lti/platforms", headers=instructor_headers()).json() == before


def test_a_refused_registration_shows_none_of_the_platforms_answer(
    tool: LiveProcess, lms: LtiPlatform
) -> None:
    with browser() as client:
        refused = register(client, registration_url(tool), configuration_url(lms), token="wrong-token")
    assert refused.status_code == 502
    assert "its registration endpoint answered 401" in refused.text
    assert "registration token missing or wrong" not in refused.text, "the platform's body was shown"


def test_a_loopback_platform_is_refused_unless_the_operator_allows_it(
    tmp_path: Path, lms: LtiPlatform
) -> None:
    env = tool_environment(tmp_path / "data", lti_allowed_networks="")
    strict = LiveProcess("serve", env, tmp_path / "serve.log").start()
    try:
        with browser() as client:
            refused = register(client, registration_url(strict), configuration_url(lms))
        assert refused.status_code == 502
        assert "the tool does not connect to '127.0.0.1': 127.0.0.1 is a loopback address" in refused.text
        assert lms.requests == [], "the tool reached a loopback address"
    finally:
        strict.stop()


@pytest.mark.parametrize("allow_http", [False, True])
def test_a_platform_registered_by_hand_needs_https(allow_http: bool) -> None:
    registration = PlatformRegistration(
        "https://lms.example.edu", "c", ("d",), "http://lms.example.edu/jwks", "https://a", "https://t"
    )
    if allow_http:
        assert registration.checked(allow_http=True) is registration
        return
    with pytest.raises(
        LtiRequestInvalid, match="a platform's jwks_url must be an https URL, found 'http://lms"
    ):
        registration.checked(allow_http=False)


def test_the_access_token_never_goes_to_a_line_item_on_another_host(
    tool: LiveProcess, lms: LtiPlatform
) -> None:
    register_by_hand(tool, lms)
    item = lms.add_line_item("link-elsewhere", score_maximum=3.0)
    elsewhere = item.replace("127.0.0.1", "localhost")  # loopback (allowed), but not the platform's host
    person = lms.add_person("learner-far", "Farah Far", LEARNER)
    with browser() as client:
        token, _ = landed(
            client, tool.url, lms.launch(client, LaunchSpec(person, "link-elsewhere", lineitem=elsewhere))
        )
        upload(client, tool.url, token, ONE_PROBLEM)

    def refused() -> list[dict[str, Any]]:
        rows = httpx.get(tool.url + "/lti/scores", headers=instructor_headers()).json()
        return [row for row in rows if row["student"] == "Farah Far" and row["error"]]

    (row,) = wait(refused, "the score refused for its foreign line item")
    assert f"{elsewhere + '/scores'!r} is not on the platform's own hosts" in row["error"]
    assert "the access token is never sent elsewhere" in row["error"]
    assert foreign(lms) == [] and lms.scores == {}


def test_a_roster_page_linking_to_another_host_is_not_followed(tool: LiveProcess, lms: LtiPlatform) -> None:
    register_by_hand(tool, lms)
    lms.memberships_next = lms.issuer.replace("127.0.0.1", "localhost") + "/memberships?page=2"
    teacher = lms.add_person("staff-rose", "Rose Roster", INSTRUCTOR)
    with browser() as client:
        token, _ = landed(client, tool.url, lms.launch(client, LaunchSpec(teacher, "link-roster")))
        imported = client.post(tool.url + "/ui/lti/roster", params={"lti_session": token})
    assert imported.status_code == 502
    assert (
        "page=2&#39; is not on the platform&#39;s own hosts" in imported.text
        or "is not on the platform" in html.unescape(imported.text)
    )
    assert ("127.0.0.1:" + str(lms.port), "/memberships") in lms.requests
    assert foreign(lms) == [], "the roster's next link took the token to another host"


def test_a_huge_jwks_is_refused_unread(tool: LiveProcess, lms: LtiPlatform) -> None:
    register_by_hand(tool, lms)
    lms.jwks_padding = 5_000_000
    person = lms.add_person("learner-huge", "Hugo", LEARNER)
    with browser() as client:
        refused = lms.launch(client, LaunchSpec(person, "link-huge"))
    assert refused.status_code == 502
    assert re.search(r"announced \d+ bytes; the tool reads at most 1000000", refused.text), refused.text


def test_made_up_key_ids_fetch_the_jwks_at_most_once_a_minute(tool: LiveProcess, lms: LtiPlatform) -> None:
    register_by_hand(tool, lms)
    person = lms.add_person("learner-kid", "Kit", LEARNER)
    with browser() as client:
        for attempt in range(5):
            refused = lms.launch(client, LaunchSpec(person, "link-kid", kid=f"made-up-{attempt}"))
            assert refused.status_code == 403
            assert f"(key id 'made-up-{attempt}'" in html.unescape(refused.text)
    assert [path for _, path in lms.requests].count("/jwks") == 1


@pytest.mark.parametrize(
    ("claims", "message"),
    [
        (
            {"azp": "another-tool"},
            "the id_token's azp (authorised party) is 'another-tool'; expected this tool's client id",
        ),
        (
            {"https://purl.imsglobal.org/spec/lti/claim/target_link_uri": "https://evil.example/lti/launch"},
            "the id_token's target_link_uri is 'https://evil.example/lti/launch'; expected",
        ),
        (
            {"https://purl.imsglobal.org/spec/lti/claim/deployment_id": "deployment-x"},
            "deployment 'deployment-x' of",
        ),
    ],
    ids=["azp-with-one-audience", "target-link-uri", "unknown-deployment"],
)
def test_a_launch_with_a_foreign_azp_or_target_is_refused_naming_no_registered_id(
    tool: LiveProcess, lms: LtiPlatform, claims: dict[str, Any], message: str
) -> None:
    register_by_hand(tool, lms)
    person = lms.add_person("learner-azp", "Ann Azp", LEARNER)
    with browser() as client:
        refused = lms.launch(client, LaunchSpec(person, "link-azp", claims=claims))
    assert refused.status_code == 403
    assert message in html.unescape(refused.text)
    assert lms.deployment_id not in refused.text, "an unauthenticated page listed the registered deployments"


def test_a_login_for_another_target_than_the_launch_url_is_refused(
    tool: LiveProcess, lms: LtiPlatform
) -> None:
    register_by_hand(tool, lms)
    params = {"iss": lms.issuer, "login_hint": "x", "target_link_uri": tool.url + "/ui/gradebook.csv"}
    refused = httpx.get(tool.url + "/lti/login", params=params)
    assert refused.status_code == 400
    assert "is not this tool's launch URL (expected " + tool.url + "/lti/launch)" in html.unescape(
        refused.text
    )


def test_the_lab_pickers_form_adds_one_link(tool: LiveProcess, lms: LtiPlatform) -> None:
    register_by_hand(tool, lms)
    teacher = lms.add_person("staff-pick", "Pia Picker", INSTRUCTOR)
    with browser() as client:
        picker = lms.launch(client, LaunchSpec(teacher, "", deep_linking=True))
        token = re.search(r'name="picker" value="([^"]+)"', picker.text)
        assert token, picker.text
        form = {"picker": token.group(1), "edition": "classic"}
        assert client.post(tool.url + "/lti/deep-link", data=form).status_code == 200
        again = client.post(tool.url + "/lti/deep-link", data=form)
    assert again.status_code == 403
    assert "this lab picker's form was sent already (it adds one link)" in html.unescape(again.text)


def test_the_origins_framing_the_lms_are_set_per_platform(tool: LiveProcess, lms: LtiPlatform) -> None:
    """Open edX: the learning MFE (its own origin) frames the LMS page that frames the tool; a browser
    checks every ancestor against frame-ancestors."""
    mfe = "https://apps.lms.example.edu"
    lms.register_tool(tool.url)
    made = httpx.post(
        tool.url + "/lti/platforms",
        json={**lms.manual_registration, "frame_ancestors": [mfe]},
        headers=instructor_headers(),
    )
    assert made.status_code == 201 and made.json()["frame_ancestors"] == [mfe], made.text
    person = lms.add_person("learner-mfe", "Mo Mfe", LEARNER)
    with browser() as client:
        _, page = landed(client, tool.url, lms.launch(client, LaunchSpec(person, "link-mfe")))
    assert f"frame-ancestors {lms.issuer} {mfe};" in page.headers["content-security-policy"]
    platform_id = made.json()["id"]
    refused = httpx.put(
        f"{tool.url}/lti/platforms/{platform_id}/frame-ancestors",
        json={"frame_ancestors": ["https://apps.example.edu/learning; script-src *"]},
        headers=instructor_headers(),
    )
    assert refused.status_code == 400
    assert (
        "a frame ancestor must be an origin such as https://apps.lms.example.edu" in refused.json()["detail"]
    )
    cleared = httpx.put(
        f"{tool.url}/lti/platforms/{platform_id}/frame-ancestors",
        json={"frame_ancestors": []},
        headers=instructor_headers(),
    )
    assert cleared.status_code == 200 and cleared.json()["frame_ancestors"] == []
