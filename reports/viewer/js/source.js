// source.js -- each robot's program with the line it is executing.
//
// The line is the one of the robot's latest sample at or before the cursor
// (samples say where the program was at their tick, trace/records.def), so
// the highlight moves at the sample rate; the panel also says the function,
// whether a handler is in service, and the watched variables' values.

function createSourcePanel(container, robot) {
  container.innerHTML = '';
  const head = document.createElement('div');
  head.className = 'source-head';
  const title = document.createElement('span');
  title.className = 'source-title';
  title.textContent = `${robot.name}: ${robot.program}`;
  title.style.color = ROBOT_COLORS[robot.robot];
  const where = document.createElement('span');
  where.className = 'source-where';
  head.append(title, where);
  const watch = document.createElement('div');
  watch.className = 'watch';
  const code = document.createElement('div');
  code.className = 'code';
  const lineEls = [null];
  const digits = String(robot.lines.length).length;
  const fragment = document.createDocumentFragment();
  robot.lines.forEach((text, i) => {
    const el = document.createElement('div');
    el.className = 'line';
    el.setAttribute('data-line', String(i + 1));
    const number = document.createElement('span');
    number.className = 'number';
    number.textContent = String(i + 1).padStart(digits, ' ');
    const body = document.createElement('span');
    body.textContent = text.replace(/\t/g, '    ');
    el.append(number, body);
    fragment.appendChild(el);
    lineEls.push(el);
  });
  code.appendChild(fragment);
  container.append(head, watch, code);

  let current = 0;

  // Puts a line in view (in the middle) without scrolling the page.
  function reveal(el) {
    const top = el.getBoundingClientRect().top - code.getBoundingClientRect().top + code.scrollTop;
    if (top < code.scrollTop + 20 || top > code.scrollTop + code.clientHeight - 40)
      code.scrollTop = Math.max(0, top - code.clientHeight / 2);
  }

  function update(t) {
    const i = sampleIndex(robot, t);
    const s = robot.samples;
    const line = i < 0 ? 0 : s.line[i];
    if (line !== current) {
      if (lineEls[current]) lineEls[current].classList.remove('current');
      current = line;
      if (lineEls[current]) {
        lineEls[current].classList.add('current');
        reveal(lineEls[current]);
      }
    }
    const fn = i < 0 ? '' : s.fn[i];
    const span = handlerAt(robot, t);
    const tps = robot.tps;
    where.textContent = (i < 0 ? '' : `line ${line}${fn ? ' in ' + fn + '()' : ' (start-up code, or main returned)'}` +
      ` at the ${(s.t[i] / tps).toFixed(2)} s sample`) +
      (span ? ` | handler ${span.handler} in service since ${(span.start / tps).toFixed(6)} s` +
        ` (it interrupted line ${span.line})` : '');
    where.classList.toggle('in-handler', Boolean(span));
    if (robot.watch.length) {
      watch.textContent = robot.watch.map((w) => {
        const k = lastAtOrBefore(w.t, t);
        const value = k < 0 ? '?' : w.v[k] === null ? '(not in scope)' : w.v[k];
        return `${w.name} = ${value}`;
      }).join('    ');
    }
  }

  return { update, currentLine: () => current };
}
