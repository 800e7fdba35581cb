// explain.js -- the Explain panel: the report of `simbot explain`, written
// by the same C++ code (reports/explain.cpp) into the page's data as lines,
// each with the tick it is about; a click on such a line seeks there.

function createExplainPanel(container, lines, seek) {
  for (const [text, t] of lines) {
    const div = document.createElement('div');
    div.textContent = text || '\u00a0';
    if (t !== null) {
      div.className = 'seek';
      div.title = 'go there';
      div.addEventListener('click', () => seek(t));
    }
    container.appendChild(div);
  }
}
