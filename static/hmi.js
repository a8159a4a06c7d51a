// Only what htmx cannot do: keyboard shortcuts, NC Start dispatch, press-and-hold continuous jog.
(function () {
  "use strict";

  function post(url, data) {
    // htmx.ajax swaps the answer (the message block) out of band, like a normal htmx request
    return htmx.ajax("POST", url, { values: data || {}, swap: "none" });
  }

  // --- keyboard: F1..F8 horizontal, Shift+F1..F8 vertical, Ctrl+Enter NC Start, Escape Reset
  document.addEventListener("keydown", function (event) {
    var match = /^F([1-8])$/.exec(event.key);
    if (match) {
      var selector = event.shiftKey ? '#vsoftkeys [data-key="S-F' + match[1] + '"]'
                                    : '#hsoftkeys [data-key="F' + match[1] + '"]';
      var key = document.querySelector(selector);
      event.preventDefault();
      if (key) key.click();
      return;
    }
    if (event.key === "Enter" && event.ctrlKey) {
      event.preventDefault();
      document.getElementById("nc-start").click();
    } else if (event.key === "Escape") {
      event.preventDefault();
      document.getElementById("reset").click();
    }
  });

  // --- NC Start: a measuring screen marks its start element with data-ncstart and
  // hx-trigger="ncstart"; without one NC Start has no function here (JOG basic screen).
  document.addEventListener("click", function (event) {
    if (!event.target.closest("#nc-start")) return;
    var target = document.querySelector("#screen [data-ncstart]");
    if (target) htmx.trigger(target, "ncstart");
    else post("/ui/ncstart");
  });

  // --- continuous jog: press and hold (only when the MCP is in "Cont" mode)
  var holding = null;
  function release() {
    if (!holding) return;
    holding.classList.remove("pressed");
    holding = null;
    post("/ui/jog/stop");
  }
  document.addEventListener("pointerdown", function (event) {
    var key = event.target.closest("#mcp[data-increment='cont'] [data-jog]");
    if (!key) return;
    event.preventDefault();
    holding = key;
    key.classList.add("pressed");
    if (key.setPointerCapture) key.setPointerCapture(event.pointerId);
    post("/ui/jog/start", { direction: key.dataset.jog });
  });
  ["pointerup", "pointercancel", "lostpointercapture"].forEach(function (name) {
    document.addEventListener(name, release);
  });
  window.addEventListener("blur", release);

  // --- feed override: show the value while the slider moves
  document.addEventListener("input", function (event) {
    if (event.target.id !== "override") return;
    var out = document.getElementById("override-value");
    if (out) out.textContent = event.target.value + " %";
  });
})();
