"""/docs (Swagger UI) and /redoc (ReDoc) from the vendored, pinned assets (static/VENDORED.md): they
work offline and under the product's Content-Security-Policy (FastAPI's inline start-up script is
allowed by its hash). "Try it out" sends the session cookie and, through static/docs-csrf.js, the
CSRF token; with "Authorize" an API token: the access levels apply as to any other client."""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.openapi.docs import get_redoc_html, get_swagger_ui_html, get_swagger_ui_oauth2_redirect_html
from fastapi.responses import HTMLResponse

from app.access.middleware import csp_for_inline_scripts

from .templating import url_path

router = APIRouter()
SWAGGER_DIR = "vendor/swagger-ui-dist-5.35.0"
REDOC_DIR = "vendor/redoc-2.5.4"
TITLE = "Measure-in-JOG HMI"


def _with_csp(response: HTMLResponse, extra: str = "") -> HTMLResponse:
    html = bytes(response.body).decode()
    return HTMLResponse(html, headers={"Content-Security-Policy": csp_for_inline_scripts(html, extra)})


@router.get("/docs", name="swagger_ui_html")
def swagger_ui(request: Request):
    bundle = url_path(request, "static", path=f"{SWAGGER_DIR}/swagger-ui-bundle.js")
    page = get_swagger_ui_html(
        openapi_url=url_path(request, "openapi"), title=f"{TITLE} - Swagger UI", swagger_js_url=bundle,
        swagger_css_url=url_path(request, "static", path=f"{SWAGGER_DIR}/swagger-ui.css"),
        swagger_favicon_url=url_path(request, "static", path=f"{SWAGGER_DIR}/favicon-32x32.png"),
        oauth2_redirect_url=url_path(request, "swagger_ui_redirect"))
    csrf = url_path(request, "static", path="docs-csrf.js")
    html = bytes(page.body).decode().replace(f'<script src="{bundle}"></script>',
                                      f'<script src="{csrf}"></script>\n    <script src="{bundle}"></script>', 1)
    if callable(request.scope.get("csrftoken")):
        request.scope["csrftoken"]()                 # the cookie docs-csrf.js reads
    return _with_csp(HTMLResponse(html))


@router.get("/docs/oauth2-redirect", name="swagger_ui_redirect")
def swagger_ui_redirect():
    return _with_csp(get_swagger_ui_oauth2_redirect_html())


@router.get("/redoc", name="redoc_html")
def redoc(request: Request):
    page = get_redoc_html(openapi_url=url_path(request, "openapi"), title=f"{TITLE} - ReDoc",
                          redoc_js_url=url_path(request, "static", path=f"{REDOC_DIR}/redoc.standalone.js"),
                          redoc_favicon_url=url_path(request, "static", path=f"{SWAGGER_DIR}/favicon-32x32.png"),
                          with_google_fonts=False)
    return _with_csp(page, "worker-src 'self' blob:")
