"""g2tess_smooth: one Bazel action per asset, running a prebuilt g2tess binary.

The action's inputs are exactly what it declares: the asset, its buffer and image files
(`srcs`), its sidecar, its folder config and `config`. Before processing, the action asks
`g2tess --print-inputs` what the run would read and fails, naming the files, if one of them is
not declared; so an action that passes reads nothing that Bazel does not hash, which is what
makes it safe to cache and to run on a remote worker. Outputs hold no paths, times or host
names, so the same inputs give the same bytes on any machine.

Only native Starlark: nothing is fetched.
"""

# The action's script. $1: the tool, $2: the file listing the declared inputs, then the
# arguments of g2tess (the asset first). Bash only, so that it needs no PATH.
_SCRIPT = """\
set -eu
tool=$1
declared=$2
shift 2
reads=$("$tool" --print-inputs "$@")
declare -A known
while IFS= read -r f; do known["$f"]=1; done < "$declared"
missing=""
while IFS= read -r f; do
  if [ -n "$f" ] && [ -z "${known[$f]+set}" ]; then missing="$missing  $f
"; fi
done <<< "$reads"
if [ -n "$missing" ]; then
  printf 'g2tess_smooth: %s reads files that are not declared (add them to srcs, sidecar or config):\\n%s' "$1" "$missing" >&2
  exit 1
fi
exec "$tool" --quiet "$@"
"""

def _g2tess_smooth_impl(ctx):
    src = ctx.file.src
    out_name = ctx.attr.out or (ctx.label.name + ".glb")
    out = ctx.actions.declare_file(out_name)
    outputs = [out]
    if out_name.endswith(".gltf"):
        outputs.append(ctx.actions.declare_file(out_name[:-len(".gltf")] + ".bin"))

    declared = [src] + ctx.files.srcs + ctx.files.sidecar + ctx.files.folder_config + ctx.files.config
    listing = ctx.actions.declare_file(ctx.label.name + ".declared_inputs")
    ctx.actions.write(listing, "".join([f.path + "\n" for f in declared]))

    args = [src.path, "-o", out.path]

    # Inside Bazel's sandbox every input is a link to the source tree, which the check that
    # uris stay in the asset's folder would refuse; the declared-inputs check above is the
    # stronger guarantee here.
    args.append("--allow-outside-uris")
    if ctx.file.sidecar:
        args += ["--sidecar", ctx.file.sidecar.path]
    if ctx.file.config:
        args += ["--config", ctx.file.config.path]
    if ctx.attr.level:
        args += ["--level", str(ctx.attr.level)]
    if ctx.attr.scheme:
        args += ["--scheme", ctx.attr.scheme]
    args += ctx.attr.flags

    ctx.actions.run_shell(
        command = _SCRIPT,
        arguments = [ctx.executable.g2tess.path, listing.path] + args,
        inputs = declared + [listing],
        tools = [ctx.executable.g2tess],
        outputs = outputs,
        mnemonic = "G2tessSmooth",
        progress_message = "Smoothing %s" % src.short_path,
    )
    return [DefaultInfo(files = depset(outputs))]

_g2tess_smooth = rule(
    implementation = _g2tess_smooth_impl,
    attrs = {
        "src": attr.label(allow_single_file = [".glb", ".gltf"], mandatory = True),
        "srcs": attr.label_list(allow_files = True, doc = "Buffer and image files the asset names."),
        "sidecar": attr.label(allow_single_file = [".toml"]),
        "folder_config": attr.label(allow_single_file = [".toml"], doc = "The g2tess.toml beside the asset."),
        "config": attr.label(allow_single_file = [".toml"], doc = "Passed as --config."),
        "level": attr.int(default = 0, doc = "Segments per edge; 0 leaves it to the configs."),
        "scheme": attr.string(default = ""),
        "flags": attr.string_list(doc = "More g2tess flags."),
        "out": attr.string(doc = "Output name (.glb or .gltf) [default: NAME.glb]."),
        "g2tess": attr.label(
            default = "//g2tess:g2tess",
            executable = True,
            allow_single_file = True,
            cfg = "exec",
        ),
    },
)

def g2tess_smooth(name, src, sidecar = None, folder_config = None, **kwargs):
    """Smooths `src`; declares its sidecar and folder config when they exist in the package.

    The sidecar (NAME.g2tess.toml beside the asset) and the folder's g2tess.toml are found by
    glob, so Bazel also notices when one is created later and runs the action again.
    """
    folder = src.rpartition("/")[0]
    prefix = folder + "/" if folder else ""
    stem = src.rpartition("/")[2].rpartition(".")[0]
    if sidecar == None:
        found = native.glob([prefix + stem + ".g2tess.toml"], allow_empty = True)
        sidecar = found[0] if found else None
    if folder_config == None:
        found = native.glob([prefix + "g2tess.toml"], allow_empty = True)
        folder_config = found[0] if found else None
    _g2tess_smooth(
        name = name,
        src = src,
        sidecar = sidecar,
        folder_config = folder_config,
        **kwargs
    )
