// The viewer's panel: what is shown (strand count, sample), colour mode, layers, the frame slider
// and play, and the checker's findings at the current frame.

function element(doc, tag, attributes = {}, children = []) {
  const node = doc.createElement(tag);
  for (const [name, value] of Object.entries(attributes)) {
    if (name === 'text') node.textContent = value;
    else node.setAttribute(name, value);
  }
  for (const child of children) node.appendChild(child);
  return node;
}

const number = (n) => n.toLocaleString('en-US');

function checkbox(doc, id, label, checked) {
  const input = element(doc, 'input', { type: 'checkbox', id });
  input.checked = checked;
  return { input, label: element(doc, 'label', { for: id }, [input, doc.createTextNode(' ' + label)]) };
}

function swatch(doc, rgb, label) {
  const box = element(doc, 'span', { class: 'swatch' });
  box.style.background = `rgb(${rgb[0]}, ${rgb[1]}, ${rgb[2]})`;
  return element(doc, 'span', { class: 'legend-item' }, [box, doc.createTextNode(label)]);
}

export function buildPanel(doc, manifest, scene, requestDraw) {
  const strands = manifest.strands;
  const frames = manifest.frames;
  const check = manifest.check;
  const panel = element(doc, 'div', { id: 'plume-panel' });
  panel.appendChild(element(doc, 'div', { class: 'title', text: `Plume · ${manifest.title}` }));

  // What is shown.
  const count = element(doc, 'div', { id: 'strand-count', 'data-total': strands.total, 'data-shown': strands.shown });
  count.textContent = strands.sample
    ? `${number(strands.shown)} of ${number(strands.total)} strands shown: a sample within the page's size, ` +
      (strands.flagged_total === 0
        ? 'spread over the groom'
        : strands.flagged_shown === strands.flagged_total
          ? `including all ${number(strands.flagged_total)} with a violation (plume check)`
          : `including ${number(strands.flagged_shown)} of the ${number(strands.flagged_total)} with a violation (plume check)`)
    : `${number(strands.total)} strands (all shown)`;
  panel.appendChild(count);

  // Colour mode.
  const select = element(doc, 'select', { id: 'color-mode' });
  for (const entry of manifest.colors) select.appendChild(element(doc, 'option', { value: entry.mode, text: entry.label }));
  const modeNote = element(doc, 'div', { id: 'mode-note', class: 'note' });
  panel.appendChild(element(doc, 'div', { class: 'row' }, [element(doc, 'label', { for: 'color-mode', text: 'Colour ' }), select]));
  panel.appendChild(modeNote);
  const legend = element(doc, 'div', { id: 'legend', class: 'note' });
  legend.append(
    swatch(doc, check.palette.inside, 'inside the skin'),
    swatch(doc, check.palette.crossing, 'crossing'),
    swatch(doc, check.palette.both, 'both'),
    swatch(doc, check.palette.touching, 'touching (near-parallel)'),
    swatch(doc, check.palette.clean, 'no problem'),
  );
  panel.appendChild(legend);

  // Layers.
  const skin = checkbox(doc, 'show-skin', 'Skin', true);
  const hair = checkbox(doc, 'show-strands', 'Strands', true);
  const guides = checkbox(doc, 'show-guides', manifest.guides.count ? `Guides (${number(manifest.guides.count)})` : 'Guides (none)', false);
  guides.input.disabled = manifest.guides.count === 0;
  const layers = [skin.label, hair.label, guides.label];
  let vanes = null;
  if (manifest.vanes) {
    vanes = checkbox(doc, 'show-vanes', 'Vanes', true);
    layers.push(vanes.label);
  }
  panel.appendChild(element(doc, 'div', { class: 'row' }, layers));

  // Frames.
  const slider = element(doc, 'input', { type: 'range', id: 'frame', min: 0, max: frames.length - 1, step: 1, value: 0 });
  const play = element(doc, 'button', { id: 'play', type: 'button', text: '▶' });
  const frameLabel = element(doc, 'span', { id: 'frame-label' });
  const frameRow = element(doc, 'div', { class: 'row frames' }, [play, slider, frameLabel]);
  if (frames.length < 2) frameRow.style.display = 'none';
  panel.appendChild(frameRow);

  // One strand: found by its id (as plume check names strands) or picked with a click.
  const find = element(doc, 'input', { type: 'text', id: 'find-strand', placeholder: 'strand id', size: 10 });
  const strandInfo = element(doc, 'div', { id: 'strand-info', class: 'note' });
  panel.appendChild(element(doc, 'div', { class: 'row' }, [element(doc, 'label', { for: 'find-strand', text: 'Find strand' }), find]));
  panel.appendChild(strandInfo);
  const ids = scene.arrays[strands.ids];

  // The checker at this frame.
  const summary = element(doc, 'div', { id: 'check-summary', class: 'note' });
  panel.appendChild(summary);
  panel.appendChild(
    element(doc, 'div', { class: 'help', text: 'Drag: turn · wheel: zoom · right drag: pan · click: a strand · space: play · ←/→: frame · g: guides' }),
  );
  doc.body.appendChild(panel);

  const update = () => {
    const index = scene.frameIndex;
    slider.value = String(index);
    frameLabel.textContent = `frame ${frames[index]} (${index + 1}/${frames.length})`;
    const entry = scene.modes.get(scene.mode);
    modeNote.textContent = entry.note || '';
    legend.style.display = scene.mode === 'problems' ? '' : 'none';
    const f = check.frames[index];
    let text = `Frame ${frames[index]}: ${number(f.points_inside)} points inside the skin (margin ${check.margin})` +
      ` in ${number(f.strands_inside)} strands; `;
    text += `crossing pairs${check.before_effects ? ' before effects' : ''} (tolerance ${Number(f.tolerance.toPrecision(3))}): ` +
      `${number(f.transversal_pairs)} transversal, ${number(f.touching_pairs)} touching`;
    if (f.transversal_flagged < f.transversal_pairs || f.touching_flagged < f.touching_pairs)
      text += ` (a sample flagged: ${number(f.transversal_flagged)} and ${number(f.touching_flagged)})`;
    if (strands.sample && f.strands_flagged > 0) text += `; ${number(f.flagged_shown)} of the ${number(f.strands_flagged)} strands with a violation shown`;
    summary.textContent = text;
    summary.classList.toggle('bad', f.points_inside > 0 || f.transversal_pairs > 0);
    if (scene.selectedStrand >= 0) {
      const flags = scene.flags()[scene.selectedStrand];
      const problem = [flags & 1 ? 'a point inside the skin' : '', flags & 2 ? 'crossing another strand' : '',
        flags & 4 ? 'touching another strand (near-parallel)' : ''].filter(Boolean).join(' and ') || 'no problem found';
      strandInfo.textContent = `Strand ${ids[scene.selectedStrand]} (white): ${problem} at frame ${frames[index]}`;
    }
  };

  /// Selects the strand with stable id `id`, or reports that the page does not hold it.
  const selectId = (id) => {
    const strand = ids.indexOf(id);
    scene.select(strand);
    if (strand < 0) {
      strandInfo.textContent = Number.isInteger(id)
        ? `Strand ${id} is not on this page` + (strands.sample ? ' (the page shows a sample of the strands)' : '')
        : 'A strand id is a whole number, as plume check prints it';
    }
    update();
    requestDraw();
    return strand;
  };
  const selectIndex = (strand) => {
    scene.select(strand);
    if (strand < 0) strandInfo.textContent = '';
    update();
    requestDraw();
  };

  const setFrame = (index) => {
    const clamped = Math.max(0, Math.min(frames.length - 1, Math.round(index)));
    scene.setFrame(clamped);
    update();
    requestDraw();
  };
  const setMode = (mode) => {
    scene.setMode(mode);
    select.value = mode;
    update();
    requestDraw();
  };
  const applyLayers = () => {
    scene.skin.visible = skin.input.checked;
    scene.skinDepth.visible = skin.input.checked;
    scene.strands.visible = hair.input.checked;
    scene.flagged.visible = hair.input.checked;
    scene.guides.visible = guides.input.checked;
    if (vanes) scene.vanes.visible = vanes.input.checked;
    requestDraw();
  };

  // Play at the groom's frame rate, looping: a range with a step (1-48:4) keeps the real speed,
  // each frame shown for as many frame periods as the step.
  let playing = false, last = 0, elapsed = 0;
  const period = 1000 / (manifest.fps || 24);
  const step = (time) => {
    if (!playing) return;
    elapsed += Math.min(time - last, 250);
    last = time;
    const index = scene.frameIndex;
    const next = (index + 1) % frames.length;
    const hold = period * (next > index ? frames[next] - frames[index] : 1);
    if (elapsed >= hold) {
      elapsed -= hold;
      setFrame(next);
    }
    requestAnimationFrame(step);
  };
  const togglePlay = () => {
    playing = !playing && frames.length > 1;
    play.textContent = playing ? '❚❚' : '▶';
    if (playing) {
      elapsed = 0;
      last = performance.now();
      requestAnimationFrame(step);
    }
  };

  find.addEventListener('keydown', (event) => {
    if (event.key === 'Enter') selectId(Number(find.value.trim()));
  });
  slider.addEventListener('input', () => setFrame(Number(slider.value)));
  play.addEventListener('click', togglePlay);
  select.addEventListener('change', () => setMode(select.value));
  for (const box of [skin, hair, guides, vanes]) if (box) box.input.addEventListener('change', applyLayers);
  doc.addEventListener('keydown', (event) => {
    // A focused slider or menu takes the arrows itself, and a focused button, box or menu the space bar.
    const target = event.target;
    if (target instanceof HTMLInputElement && target.type === 'text') return;
    const slider = target instanceof HTMLInputElement && target.type === 'range';
    const arrowsTaken = slider || target instanceof HTMLSelectElement;
    const spaceTaken = !slider && (target instanceof HTMLInputElement || target instanceof HTMLButtonElement ||
      target instanceof HTMLSelectElement);
    if (event.key === ' ' && !spaceTaken) {
      togglePlay();
      event.preventDefault();
    } else if (event.key === 'ArrowRight' && !arrowsTaken) {
      setFrame(scene.frameIndex + 1);
    } else if (event.key === 'ArrowLeft' && !arrowsTaken) {
      setFrame(scene.frameIndex - 1);
    } else if (event.key === 'g') {
      guides.input.checked = !guides.input.checked;
      applyLayers();
    }
  });
  return { update, setFrame, setMode, selectId, selectIndex };
}
