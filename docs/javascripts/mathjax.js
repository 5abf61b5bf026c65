// MathJax 3 for the maths of the site: the $...$ of the docstrings and pages, which
// pymdownx.arithmatex (generic mode) wraps as \(...\) in elements of class "arithmatex",
// and the $...$ of the notebooks' Markdown cells and Markdown outputs, which
// mkdocs-jupyter leaves as written in elements of class "jp-MarkdownOutput". Nothing else
// is typeset (a "$" in code or prose stays a dollar); tests/test_docs.py checks the
// built pages against these classes and delimiters.
window.MathJax = {
  tex: {
    inlineMath: [["\\(", "\\)"], ["$", "$"]],
    displayMath: [["\\[", "\\]"], ["$$", "$$"]],
    processEscapes: true,
    processEnvironments: true
  },
  options: {
    ignoreHtmlClass: ".*|",
    processHtmlClass: "arithmatex|jp-MarkdownOutput"
  }
};

// material's instant navigation swaps pages without a reload: typeset each new one
document$.subscribe(() => {
  MathJax.startup.output.clearCache();
  MathJax.typesetClear();
  MathJax.texReset();
  MathJax.typesetPromise();
});
