// Render the \( ... \) and \[ ... \] spans that pymdownx.arithmatex (generic mode) leaves in
// elements of class "arithmatex", with the vendored KaTeX. Material's instant navigation
// replaces the page content without a reload, so render on each of its page events.
function renderMath() {
  for (const element of document.querySelectorAll(".arithmatex")) {
    renderMathInElement(element, {
      delimiters: [
        { left: "\\(", right: "\\)", display: false },
        { left: "\\[", right: "\\]", display: true },
      ],
      throwOnError: false,
    });
  }
}
if (typeof document$ !== "undefined") {
  document$.subscribe(renderMath);
} else {
  document.addEventListener("DOMContentLoaded", renderMath);
}
