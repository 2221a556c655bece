// Tells the LMS that dynamic registration is done (LTI Dynamic Registration: org.imsglobal.lti.close).
(function () {
  "use strict";
  (window.opener || window.parent).postMessage({ subject: "org.imsglobal.lti.close" }, "*");
})();
