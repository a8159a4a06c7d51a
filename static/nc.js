// Line numbers beside the program editors (MDA screen, program manager): the gutter follows the
// text and its scrolling. Event delegation, so that htmx swaps need nothing; loaded once.
(function () {
  "use strict";
  if (window.ncEditor) return;
  window.ncEditor = true;
  function gutterOf(area) {
    var editor = area.closest(".editor");
    return editor ? editor.querySelector(".gutter") : null;
  }
  function number(area) {
    var gutter = gutterOf(area);
    if (!gutter) return;
    var lines = area.value.split("\n").length + 1;
    var text = "";
    for (var i = 1; i <= lines; i++) text += i + "\n";
    if (gutter.textContent !== text) gutter.textContent = text;
    gutter.scrollTop = area.scrollTop;
  }
  document.addEventListener("input", function (event) {
    if (event.target.matches(".editor textarea")) number(event.target);
  });
  // cycle support (program manager): where the cycle goes / which call is read = the cursor
  function cursor(area) {
    var form = area.closest("form");
    var field = form ? form.querySelector("input[name=cursor]") : null;
    if (field) field.value = String(area.selectionStart);
  }
  ["keyup", "click", "select", "input"].forEach(function (kind) {
    document.addEventListener(kind, function (event) {
      if (event.target.matches && event.target.matches(".editor textarea")) cursor(event.target);
    });
  });
  document.addEventListener("scroll", function (event) {
    var area = event.target;
    if (area.matches && area.matches(".editor textarea")) {
      var gutter = gutterOf(area);
      if (gutter) gutter.scrollTop = area.scrollTop;
    }
  }, true);
})();
