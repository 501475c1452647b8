FROM debian:bookworm
RUN apt-get update \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends bash ca-certificates \
 && rm -rf /var/lib/apt/lists/*
COPY . /opt/beamfx
WORKDIR /opt/beamfx
RUN scripts/install.sh
ENV PATH=/opt/beamfx/.venv/bin:$PATH \
    SETUPTOOLS_USE_DISTUTILS=stdlib \
    VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow \
    OMPI_MCA_rmaps_base_oversubscribe=1 \
    PYTHONUNBUFFERED=1
CMD ["beamfx", "run"]
