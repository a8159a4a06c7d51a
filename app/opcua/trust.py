"""The OPC UA trust list (design.md §10.8): a client certificate opens a secure channel only when
the administrator trusted it. ``<data dir>/opcua/pki/trusted/`` holds the trusted certificates
(DER or PEM), ``…/pki/rejected/`` keeps each refused one (DER, named by its SHA-256 thumbprint) so
the administrator can look at it and trust it: ``python -m app opcua trust add|list|remove``."""

from __future__ import annotations

import logging
from pathlib import Path

from asyncua import ua
from asyncua.common.utils import ServiceError
from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization

log = logging.getLogger(__name__)


def pki_folder(data_dir: Path) -> Path:
    return data_dir / "opcua" / "pki"


def thumbprint(certificate: x509.Certificate) -> str:
    return certificate.fingerprint(hashes.SHA256()).hex()


def load_certificate(path: Path) -> x509.Certificate:
    data = path.read_bytes()
    try:
        return x509.load_der_x509_certificate(data)
    except ValueError:
        return x509.load_pem_x509_certificate(data)


class TrustList:
    def __init__(self, data_dir: Path):
        self.trusted = pki_folder(data_dir) / "trusted"
        self.rejected = pki_folder(data_dir) / "rejected"

    def entries(self) -> list[dict]:
        """The trusted certificates: thumbprint, subject, file name."""
        found = []
        for path in sorted(self.trusted.glob("*")) if self.trusted.is_dir() else []:
            try:
                certificate = load_certificate(path)
            except (OSError, ValueError):
                log.warning("OPC UA trust list: %s is no certificate", path.name)
                continue
            found.append({"thumbprint": thumbprint(certificate), "subject": certificate.subject.rfc4514_string(),
                          "file": path.name})
        return found

    def is_trusted(self, certificate: x509.Certificate) -> bool:
        return thumbprint(certificate) in {entry["thumbprint"] for entry in self.entries()}

    def add(self, path: Path) -> dict:
        """Trusts the certificate in ``path`` (ValueError when it is none)."""
        certificate = load_certificate(path)
        self.trusted.mkdir(parents=True, exist_ok=True)
        target = self.trusted / f"{thumbprint(certificate)}.der"
        target.write_bytes(certificate.public_bytes(serialization.Encoding.DER))
        (self.rejected / target.name).unlink(missing_ok=True)
        return {"thumbprint": thumbprint(certificate), "subject": certificate.subject.rfc4514_string(),
                "file": target.name}

    def remove(self, which: str) -> list[str]:
        """Removes the trusted certificates whose thumbprint starts with ``which`` or whose file
        is named ``which``; the names removed."""
        gone = []
        for entry in self.entries():
            if entry["file"] == which or (len(which) >= 8 and entry["thumbprint"].startswith(which.lower())):
                (self.trusted / entry["file"]).unlink()
                gone.append(entry["file"])
        return gone

    async def validate(self, certificate: x509.Certificate, _app: ua.ApplicationDescription) -> None:
        """asyncua's certificate validator: an unknown certificate is kept in ``rejected`` and refused."""
        if self.is_trusted(certificate):
            return
        try:
            self.rejected.mkdir(parents=True, exist_ok=True)
            (self.rejected / f"{thumbprint(certificate)}.der").write_bytes(
                certificate.public_bytes(serialization.Encoding.DER))
        except OSError as exc:
            log.warning("OPC UA: a rejected certificate could not be kept: %s", exc)
        log.warning("OPC UA: client certificate %s (%s) is not trusted", thumbprint(certificate)[:16],
                    certificate.subject.rfc4514_string())
        raise ServiceError(ua.StatusCodes.BadCertificateUntrusted)
