# The benchmark corpus (sourced by scripts/benchmarks.sh and scripts/import_corpus.sh):
# make_corpus AMC DATA_DIR CORPUS_DIR writes the hierarchies into CORPUS_DIR and lists them, in
# table order, in the array corpus_models. Deterministic: the same files on every run, so with
# AMC_REUSE_CORPUS=1 a model whose file exists is not made again.
make_corpus() {
  local amc=$1 data=$2 corpus=$3 model file mean_faces gauss_faces criterion faces
  corpus_models=()
  mkdir -p "$corpus"
  if [[ ! -d $data ]]; then
    echo "note: $data is absent; the remeshed surface models are skipped, only the procedural models are made" >&2
  else
    # Every real model adaptively remeshed by mean and by Gauss curvature (the paper's feline_mean /
    # feline_gauss): a base asked for 500 triangles (the remesher doubles it while it folds over or
    # strays: 500-3,998 on these models), refined up to level 5 until about `faces` leaves.
    # model      file            faces (mean)  faces (gauss)
    while read -r model file mean_faces gauss_faces; do
      for criterion in mean gauss; do
        faces=$mean_faces
        [[ $criterion == gauss ]] && faces=$gauss_faces
        if [[ ${AMC_REUSE_CORPUS:-0} != 1 || ! -s $corpus/${model}_$criterion.amh ]]; then
          "$amc" -f refine --input "$data/$file" --criterion "$criterion" --faces "$faces" --base-faces 500 --max-level 5 \
            -o "$corpus/${model}_$criterion.amh" > /dev/null || return 1
        fi
        corpus_models+=("$corpus/${model}_$criterion.amh")
      done
    done <<'LIST'
bunny-hr    bunny-hr.obj    100000 100000
horse       horse.obj       100000 100000
feline      feline.off      250000 200000
venus       venus.off       140000 140000
fandisk     fandisk.obj     100000 100000
rocker-arm  rocker-arm.obj  100000 100000
femur       femur.obj       100000 100000
camelhead   camelhead.off   100000 100000
mountain    mountain.obj    100000 100000
LIST
  fi
  # Planar finite-element models, a uniform and a random refinement.
  "$amc" -f refine --model lshape --max-level 10 -o "$corpus/lshape.amh" > /dev/null || return 1
  "$amc" -f refine --model front --steps 3 --max-level 9 -o "$corpus/front" > /dev/null || return 1
  "$amc" -f refine --model uniform --levels 7 -o "$corpus/uniform.amh" > /dev/null || return 1
  "$amc" -f refine --model random --faces 150000 --seed 7 -o "$corpus/random.amh" > /dev/null || return 1
  corpus_models+=("$corpus/lshape.amh" "$corpus"/front_*.amh "$corpus/uniform.amh" "$corpus/random.amh")
}

# Held-out models (issue 30): the meshes of DATA_DIR the corpus above does not use, remeshed the
# same way (about 100,000 faces, base asked for 500 triangles, up to level 5, mean and Gauss
# curvature), for checking on unseen meshes what was tuned on the corpus. make_heldout_corpus AMC
# DATA_DIR CORPUS_DIR lists them in heldout_models; AMC_REUSE_CORPUS=1 as above.
make_heldout_corpus() {
  local amc=$1 data=$2 corpus=$3 model file criterion
  heldout_models=()
  mkdir -p "$corpus"
  while read -r model file; do
    for criterion in mean gauss; do
      if [[ ${AMC_REUSE_CORPUS:-0} != 1 || ! -s $corpus/${model}_$criterion.amh ]]; then
        "$amc" -f refine --input "$data/$file" --criterion "$criterion" --faces 100000 --base-faces 500 --max-level 5 \
          -o "$corpus/${model}_$criterion.amh" > /dev/null || return 1
      fi
      heldout_models+=("$corpus/${model}_$criterion.amh")
    done
  done <<'LIST'
bunny          bunny.obj
elephant       elephant-sr-l2.obj
bunny-sr       bunny-sr-l3.obj
venus-coarse   venus-coarse.off
rabbit-coarse  rabbit-coarse.off
LIST
}
