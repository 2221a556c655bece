// LTI client-side OIDC storage: the platform keeps a login's secret for the tool, through postMessage
// (lti.put_data before going on to the platform's authorisation; lti.get_data at the launch, which is then
// posted again with the secret). Messages go to the platform's storage frame, to the origin of its
// authorisation URL only, and only its answers to this page's message are read.
(function () {
  "use strict";
  var element = document.getElementById("lti-storage");
  var data = element.dataset;
  var parent = window.parent;
  var target = data.target === "_parent" ? parent : parent.frames[data.target];
  var messageId = "gymgrade-" + Math.random().toString(36).slice(2);
  var finished = false;

  function finish(value) {
    if (finished) {
      return;
    }
    finished = true;
    if (data.action === "put") {
      window.location.replace(data.next);
    } else {
      document.getElementById("lti-storage-value").value = value || "";
      document.getElementById("lti-storage-form").submit();
    }
  }

  window.addEventListener("message", function (event) {
    var answer = event.data;
    if (event.origin !== data.origin || !answer || answer.message_id !== messageId) {
      return;
    }
    finish(answer.error ? "" : answer.value);
  });
  if (!target) {
    finish("");
    return;
  }
  var message = { subject: "lti." + data.action + "_data", message_id: messageId, key: data.key };
  if (data.action === "put") {
    message.value = data.value;
  }
  target.postMessage(message, data.origin);
  window.setTimeout(function () { finish(""); }, 5000);
})();
