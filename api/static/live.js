// Refreshes a submission's live section once a second until its grading has finished.
(function () {
  "use strict";
  var section = document.getElementById("live");
  if (!section) {
    return;
  }
  function finished() {
    return section.querySelector('[data-final="true"]') !== null;
  }
  function refresh() {
    if (finished()) {
      return;
    }
    fetch(section.dataset.src, { credentials: "same-origin", cache: "no-store" })
      .then(function (response) {
        return response.ok ? response.text() : null;
      })
      .then(function (html) {
        if (html !== null) {
          section.innerHTML = html;
        }
      })
      .catch(function () {})
      .finally(function () {
        window.setTimeout(refresh, 1000);
      });
  }
  window.setTimeout(refresh, 1000);
})();
