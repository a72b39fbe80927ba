# Sourced by the set-up scripts: apt_get runs apt-get holding one lock for the whole machine,
# so the set-ups that scripts/setup.sh --test runs side by side install one after another
# (apt-get itself refuses to start while another holds dpkg's lock), and waits for dpkg's own
# lock as well when something else is installing.
apt_get() {
  DEBIAN_FRONTEND=noninteractive flock "${TMPDIR:-/tmp}/cadkg-apt.lock" \
    apt-get -o DPkg::Lock::Timeout=600 "$@"
}
