"""The OpenAPI document describes the API as it answers (issue [operator-ux] item 11): the error
envelope, every 4xx, an example per operation; and a real refusal matches the documented schema."""

from __future__ import annotations

import json

METHODS = {"get", "put", "post", "delete", "patch"}


def _operations(doc):
    for path, item in doc["paths"].items():
        for method, operation in item.items():
            if method in METHODS:
                yield path, method, operation


def test_every_operation_documents_the_error_envelope_and_an_example(client):
    doc = client.get("/openapi.json").json()
    assert "HTTPValidationError" not in doc["components"]["schemas"]
    assert '"detail"' not in json.dumps(doc)                      # FastAPI's default shape is gone
    body = doc["components"]["schemas"]["ErrorBody"]
    assert {"code", "message", "field"} <= set(body["properties"])
    operations = list(_operations(doc))
    assert len(operations) > 40
    for path, method, operation in operations:
        responses = operation["responses"]
        assert responses["422"]["content"]["application/json"]["schema"] == {"$ref": "#/components/schemas/ErrorEnvelope"}
        if method != "get":
            assert {"400", "409"} <= set(responses), (method, path)
        if "{" in path:
            assert "404" in responses, (method, path)
        examples = [c.get("example") for r in responses.values() for c in r.get("content", {}).values()]
        assert any(e is not None for e in examples), (method, path)


def test_a_real_refusal_has_the_documented_shape(client):
    doc = client.get("/openapi.json").json()
    documented = doc["paths"]["/api/offsets/{name}"]["put"]["responses"]["422"]
    answer = client.put("/api/offsets/G54", json={"trans": {"X": "abc"}})
    assert answer.status_code == 422
    body = answer.json()
    assert set(body) == {"error"} and {"code", "message"} <= set(body["error"])
    assert set(body["error"]) <= set(documented["content"]["application/json"]["example"]["error"])
    missing = client.get("/api/log/987654")
    assert missing.status_code == 404 and missing.json()["error"]["code"] == "not_found"
