// Posts a deep linking response back to the LMS as soon as the page is shown (the button is the fallback).
(function () {
  "use strict";
  var form = document.getElementById("lti-post");
  if (form) {
    form.submit();
  }
})();
