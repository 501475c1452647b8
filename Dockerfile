FROM debian:bookworm
RUN apt-get update \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends bash ca-certificates \
 && rm -rf /var/lib/apt/lists/*
COPY . /opt/beamfx
WORKDIR /opt/beamfx
RUN scripts/install.sh
# XDG_CACHE_HOME: the JIT cache is /var/cache/beamfx/fenics for every user of the image
ENV PATH=/opt/beamfx/.venv/bin:$PATH \
    SETUPTOOLS_USE_DISTUTILS=stdlib \
    VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow \
    OMPI_MCA_rmaps_base_oversubscribe=1 \
    PYTHONUNBUFFERED=1 \
    XDG_CACHE_HOME=/var/cache/beamfx
# compile the kernels of the default scene, the common cases, the demos and the docs' examples
# (a few minutes), so that `docker run` starts warm; writable for `docker run -u` users too
RUN beamfx warm demos/scenes docs/scenes.md && chmod -R a+rwX /var/cache/beamfx
CMD ["beamfx", "run"]
