"""Answers schemathesis's contract checks want (issue 25 item 7): a 405 names the allowed methods
(Allow), and an empty ``Authorization: Bearer`` of a trainer-mode client counts as no credentials."""

from __future__ import annotations

import pytest


def test_a_405_names_the_allowed_methods(client):
    answer = client.delete("/api/machine")
    assert answer.status_code == 405 and answer.json()["error"]["code"] == "method_not_allowed"
    assert set(answer.headers["Allow"].replace(" ", "").split(",")) == {"GET"}


def test_an_empty_bearer_is_no_credentials_in_trainer_mode(client):
    assert client.get("/api/machine", headers={"Authorization": "Bearer "}).status_code == 200
    assert client.put("/api/machine/override", json={"feed": 80.0},
                      headers={"Authorization": "Bearer "}).status_code == 200


def test_an_empty_bearer_is_still_refused_with_sign_in_on(app, client):
    app.state.access.add_user("anna", 3, "anna-pw-333")
    answer = client.get("/api/machine", headers={"Authorization": "Bearer "})
    assert answer.status_code == 401


def test_a_405_names_every_method_of_the_path(client):
    """FastAPI keeps one route per method: the Allow of a 405 names them all, not the first one's."""
    answer = client.request("PATCH", "/api/tools/3")
    assert answer.status_code == 405
    assert set(answer.headers["Allow"].replace(" ", "").split(",")) == {"GET", "PUT", "DELETE"}
    answer = client.request("OPTIONS", "/api/job")
    assert set(answer.headers["Allow"].replace(" ", "").split(",")) == {"GET", "PUT", "DELETE"}
    # a literal path names its own methods, not those of a parameter's path it also matches
    # (/api/measure/{session_id} has DELETE, /api/measure/current only GET)
    answer = client.request("OPTIONS", "/api/measure/current")
    assert answer.status_code == 405 and answer.headers["Allow"] == "GET"
    answer = client.request("OPTIONS", "/api/measure/abc123")
    assert set(answer.headers["Allow"].replace(" ", "").split(",")) == {"GET", "DELETE"}


def _parameter(schema: dict, method: str, path: str, name: str) -> dict:
    for parameter in schema["paths"][path][method]["parameters"]:
        if parameter["name"] == name:
            return parameter["schema"]
    raise AssertionError(f"{method.upper()} {path} has no parameter {name}")


def _bounds(parameter: dict) -> tuple:
    options = parameter.get("anyOf", [parameter])
    number = next(o for o in options if o.get("type") == "integer")
    return number.get("minimum"), number.get("maximum")


def test_the_schema_bounds_the_numbers_a_path_or_query_names(app):
    """schemathesis ST202/ST201 (issue 25 item 7): the schema states the ranges the services check
    (tool numbers 1..9999, probe records 1..99, points P1..P12), so a schema-valid number is taken
    and the test below shows that one outside is refused."""
    schema = app.openapi()
    for method in ("get", "put", "delete"):
        assert _bounds(_parameter(schema, method, "/api/tools/{t}", "t")) == (1, 9999)
    for method, path in [("get", "/api/probes/{n}"), ("put", "/api/probes/{n}"), ("get", "/api/tool-probes/{n}"),
                         ("put", "/api/tool-probes/{n}"), ("post", "/api/probes/{n}/repeatability"),
                         ("get", "/api/probes/{n}/history")]:
        assert _bounds(_parameter(schema, method, path, "n")) == (1, 99), path
    assert _bounds(_parameter(schema, "post", "/api/measure/{session_id}/points/{n}/invalidate", "n")) == (1, 12)
    assert _bounds(_parameter(schema, "get", "/api/measure/{session_id}/plan", "point")) == (1, 12)


def test_the_schema_names_the_tasks_of_the_registry(app):
    from app.workflow.tasks import TASKS

    schema = app.openapi()
    readiness = _parameter(schema, "get", "/api/readiness", "task")
    assert set(readiness["enum"]) == set(TASKS) and "hole.1" in readiness["enum"]
    body = schema["components"]["schemas"]["CreateBody"]["properties"]["task"]
    assert set(body["enum"]) == set(TASKS)


def test_what_the_schema_refuses_the_api_refuses(client):
    """The bounds are the services' own: outside them a 422 naming the parameter, nothing stored."""
    for method, url, field in [("put", "/api/tools/0", "t"), ("put", "/api/tools/10000", "t"),
                               ("get", "/api/probes/100", "n"), ("get", "/api/tool-probes/0", "n"),
                               ("get", "/api/probes/100/history", "n"), ("get", "/api/readiness?task=nope", "task")]:
        answer = client.request(method.upper(), url, json={"length": 1.0} if method == "put" else None)
        assert answer.status_code == 422, (url, answer.text)
        assert answer.json()["error"]["field"] == field, url
    assert client.get("/api/tools/10000").status_code == 422
    assert 10000 not in [tool["t"] for tool in client.get("/api/tools").json()]


def test_the_schema_states_the_rules_of_a_new_user_and_a_program_name(app, client):
    """The body fields the services check by rule: a schema that says so (the password policy of
    docs/hardening.md: at least 8 characters; levels 1..3), and the API refuses what it refuses."""
    import re

    schemas = app.openapi()["components"]["schemas"]
    user = schemas["UserBody"]["properties"]
    assert user["password"]["minLength"] == 8
    assert (user["level"]["minimum"], user["level"]["maximum"]) == (1, 3)
    name = re.compile(user["name"]["pattern"])
    assert name.search("anna.k@plant-2") and not name.search("") and not name.search("-anna")
    program = re.compile(schemas["ProgramBody"]["properties"]["name"]["pattern"])
    assert program.search("BORE1") and not program.search("1BORE") and not program.search("")
    assert client.post("/api/programs", json={"name": "1BORE", "text": "M30"}).status_code == 422
    assert client.post("/api/users", json={"name": "-anna", "password": "long-enough-1", "level": 3}).status_code == 422
    assert client.post("/api/users", json={"name": "anna", "password": "short", "level": 3}).status_code == 422
    assert client.get("/api/users").json() == []


@pytest.mark.parametrize("target", [False, 0, ["G54"]])
def test_a_measuring_target_of_the_wrong_type_is_refused(client, target):
    """schemathesis ST201: ``"target": false`` used to open a session on the default target."""
    answer = client.post("/api/measure", json={"task": "edge.set", "target": target,
                                               "params": {"axis": "Z", "direction": "-", "setpoint": 0}})
    assert answer.status_code == 400 and answer.json()["error"]["field"] == "target"
    assert client.get("/api/measure/current").json() is None
