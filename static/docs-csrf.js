// Swagger UI's "Try it out" in a signed-in browser: same-origin writes carry the CSRF token (the
// csrftoken cookie's value as X-CSRFToken), as the HMI's own pages do with hx-headers; the access
// levels then apply as to any request (design.md §9.2). Loaded before the Swagger UI bundle.
(function () {
  "use strict";
  var original = window.fetch;
  if (!original) return;
  function token() {
    var match = document.cookie.match(/(?:^|;\s*)csrftoken=([^;]*)/);
    return match ? decodeURIComponent(match[1]) : "";
  }
  window.fetch = function (input, init) {
    init = init || {};
    var request = typeof input === "string" || input instanceof URL ? null : input;
    var method = (init.method || (request && request.method) || "GET").toUpperCase();
    var url = new URL(request ? request.url : String(input), window.location.href);
    if (url.origin === window.location.origin && ["GET", "HEAD", "OPTIONS"].indexOf(method) < 0) {
      var headers = new Headers(init.headers || (request && request.headers) || {});
      if (!headers.has("X-CSRFToken")) headers.set("X-CSRFToken", token());
      init = Object.assign({}, init, { headers: headers });
    }
    return original.call(this, input, init);
  };
})();
