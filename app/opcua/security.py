"""The endpoint's security (README "OPC UA"): security policies None, Basic256Sha256 and
Aes256Sha256RsaPss (Sign, SignAndEncrypt), user tokens Anonymous and UserName.

The server's certificate is self-signed, made at the first start into ``<data dir>/opcua/``
(``server_key.pem``, readable by the owner only, and ``server_cert.der``, valid one year, renewed
when it expires or the host name changes). With it a password is never sent in clear: on the None
endpoint the UserName token is encrypted with the server's key (Basic256Sha256). A client
certificate must be in the trust list (app/opcua/trust.py), else the session is refused. When the folder cannot be written the endpoint offers None with
an unencrypted UserName token and says so in the log.
"""

from __future__ import annotations

import logging
import os
import socket
from pathlib import Path

from asyncua import Server, ua
from asyncua.crypto.cert_gen import (
    dump_private_key_as_pem,
    generate_private_key,
    setup_self_signed_certificate,
)
from cryptography.x509.oid import ExtendedKeyUsageOID

from .trust import TrustList
from .users import HmiRuleset

log = logging.getLogger(__name__)
KEY_FILE, CERT_FILE = "server_key.pem", "server_cert.der"
SECURE = [ua.SecurityPolicyType.Basic256Sha256_SignAndEncrypt, ua.SecurityPolicyType.Basic256Sha256_Sign,
          ua.SecurityPolicyType.Aes256Sha256RsaPss_SignAndEncrypt, ua.SecurityPolicyType.Aes256Sha256RsaPss_Sign]


async def configure(server: Server, data_dir: Path, app_uri: str) -> list[str]:
    """Set policies, tokens and certificate; returns the policy names offered."""
    server.set_identity_tokens([ua.AnonymousIdentityToken, ua.UserNameIdentityToken])
    policies = [ua.SecurityPolicyType.NoSecurity]
    try:
        key, cert = await certificate(data_dir, app_uri)
    except OSError as exc:
        log.warning("OPC UA: no server certificate (%s): only security policy None, passwords unencrypted", exc)
    else:
        await server.load_certificate(str(cert))
        await server.load_private_key(str(key))
        policies += SECURE
        server.set_certificate_validator(TrustList(data_dir).validate)     # unknown client certificates: refused
    # asyncua annotates SimpleRoleRuleset but takes any PermissionRuleset (it calls check_validity only)
    server.set_security_policy(policies, permission_ruleset=HmiRuleset())  # type: ignore[arg-type]
    return [p.name for p in policies]


async def certificate(data_dir: Path, app_uri: str) -> tuple[Path, Path]:
    folder = data_dir / "opcua"
    folder.mkdir(parents=True, exist_ok=True)
    key, cert = folder / KEY_FILE, folder / CERT_FILE
    if not key.is_file():                    # born readable by the owner only
        pem = dump_private_key_as_pem(generate_private_key())
        descriptor = os.open(key, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(descriptor, "wb") as out:
            out.write(pem)
    await setup_self_signed_certificate(      # (re)makes the certificate when missing or no longer valid
        key, cert, app_uri, socket.gethostname(), [ExtendedKeyUsageOID.SERVER_AUTH],
        {"countryName": "DE", "organizationName": "JOG Measure HMI", "commonName": "JOG Measure HMI OPC UA"})
    return key, cert
